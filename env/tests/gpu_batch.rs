//! A vector env with `backend = "gpu"` keeps every world's grid pheromones in one resident GPU batch
//! (fields, trail deposits and colour sensing of all worlds together each step): its observations,
//! rewards and flags equal the CPU backend's, step for step, for `trail`, `foraging` and agents laying
//! pheromone by action, through episode ends (both autoreset modes) and resets of some worlds, and its
//! fields read back within the GPU's stated bound. Run with `--features gpu` (lavapipe will do).
#![cfg(feature = "gpu")]
use colcos_env::{ActionKind, Actions, AutoresetMode, EnvConfig, EnvError, ScenarioSource, VecEnv};
use colcos_sim::field::{BackendChoice, FieldModel};

const TRAIL: &str = include_str!("../scenarios/trail.toml");
const SCRIPTED: &str = r#"deposits = [{ pheromone = "red", kernel = { shape = "disc", radius = 0.008 }, rate = 3.0 }]"#;

fn cfg(task: &str, text: Option<String>, worlds: usize, backend: BackendChoice) -> EnvConfig {
    let mut c = EnvConfig::new(task);
    if let Some(t) = text {
        c.scenario = ScenarioSource::Text(t);
    }
    c.num_envs = worlds;
    c.max_cycles = 7;
    c.seed = 11;
    c.num_threads = Some(2);
    c.backend = Some(backend);
    c
}

/// The GPU env of `c`, or `None` (skipping) without an adapter unless `COLCOS_REQUIRE_GPU=1`.
fn gpu_env(c: &EnvConfig) -> Option<VecEnv> {
    match VecEnv::new(c) {
        Ok(e) => Some(e),
        Err(EnvError::Backend(m)) => {
            if std::env::var("COLCOS_REQUIRE_GPU").is_ok_and(|v| v == "1") {
                panic!("COLCOS_REQUIRE_GPU=1 but {m}");
            }
            eprintln!("skipping: {m}");
            None
        }
        Err(e) => panic!("{e}"),
    }
}

/// The batch `c` on the GPU and the same batch on the CPU, or `None` (skipping) as [`gpu_env`].
fn gpu_and_cpu(mut c: EnvConfig) -> Option<(VecEnv, VecEnv)> {
    c.backend = Some(BackendChoice::Gpu);
    let gpu = gpu_env(&c)?;
    c.backend = Some(BackendChoice::Cpu);
    Some((gpu, VecEnv::new(&c).unwrap()))
}

/// `trail` with `worlds` worlds of episodes of `max_cycles` steps, on the GPU and on the CPU, both
/// reset, or `None` (skipping) as [`gpu_env`].
fn reset_trail_pair(worlds: usize, max_cycles: u64) -> Option<(VecEnv, VecEnv)> {
    let mut c = cfg("trail", None, worlds, BackendChoice::Gpu);
    c.max_cycles = max_cycles;
    let (mut gpu, mut cpu) = gpu_and_cpu(c)?;
    gpu.reset(None, None).unwrap();
    cpu.reset(None, None).unwrap();
    Some((gpu, cpu))
}

/// The largest difference between two grids' values, relative to the CPU grid `c`'s largest.
fn relative_error(g: &FieldModel, c: &FieldModel) -> f32 {
    let (FieldModel::Grid(g), FieldModel::Grid(c)) = (g, c) else {
        panic!("grid pheromones")
    };
    let scale = c.values().iter().fold(1e-12f32, |m, v| m.max(v.abs()));
    (g.values().iter().zip(c.values()))
        .map(|(a, b)| (a - b).abs() / scale)
        .fold(0f32, f32::max)
}

/// Continuous actions of step `step`: every agent different, some of them reversing.
fn actions(env: &VecEnv, step: usize) -> Vec<f32> {
    let s = env.spec();
    let width = s.action.flat_len();
    (0..s.num_envs * s.num_agents * width)
        .map(|k| (((k * 37 + step * 13) % 11) as f32 / 5.0) - 1.0)
        .map(|v| v.clamp(-1.0, 1.0))
        .collect()
}

/// Steps both envs `steps` times with the same actions (resetting the worlds `resets` names at the
/// steps it names, in both), asserting equal outputs after every step; returns how many world-steps
/// ended an episode.
fn lockstep(
    gpu: &mut VecEnv,
    cpu: &mut VecEnv,
    steps: usize,
    resets: &[(usize, Vec<bool>)],
) -> usize {
    assert_eq!(gpu.backend().name(), "gpu", "{}", gpu.backend().describe());
    assert!(gpu.backend().is_batched(), "{}", gpu.backend().describe());
    assert!(gpu.world(0).unwrap().external_grids());
    assert_eq!(cpu.backend().name(), "cpu");
    gpu.reset(None, None).unwrap();
    cpu.reset(None, None).unwrap();
    assert_eq!(gpu.outputs().obs(), cpu.outputs().obs(), "after reset");
    let mut ends = 0;
    for step in 0..steps {
        for (at, mask) in resets {
            if *at == step {
                gpu.reset(None, Some(mask)).unwrap();
                cpu.reset(None, Some(mask)).unwrap();
                assert_eq!(
                    gpu.outputs().obs(),
                    cpu.outputs().obs(),
                    "step {step}: after a partial reset"
                );
            }
        }
        let a = actions(gpu, step);
        gpu.step(Actions::Continuous(&a)).unwrap();
        cpu.step(Actions::Continuous(&a)).unwrap();
        let worst = (gpu.outputs().obs().iter().zip(cpu.outputs().obs()))
            .map(|(g, c)| (g - c).abs())
            .fold(0f32, f32::max);
        assert_eq!(
            gpu.outputs().obs(),
            cpu.outputs().obs(),
            "step {step}: observations differ by {worst}"
        );
        // Every other output alike, each named where it differs.
        macro_rules! same {
            ($($output:ident),+) => {
                $(assert_eq!(
                    gpu.outputs().$output(),
                    cpu.outputs().$output(),
                    "step {step}: {}",
                    stringify!($output)
                );)+
            };
        }
        same!(rewards, terminated, truncated, final_mask, final_obs);
        ends += cpu.outputs().truncated().iter().filter(|&&t| t).count();
    }
    ends
}

/// After [`VecEnv::sync_fields`], every grid field of every world within 1e-5 of the CPU's (relative
/// to the field's largest value), and something laid.
fn fields_agree(gpu: &mut VecEnv, cpu: &VecEnv) {
    gpu.sync_fields().unwrap();
    let mut nonzero = 0;
    for w in 0..cpu.spec().num_envs {
        let phs = gpu.world(w).unwrap().pheromones();
        for (k, (g, c)) in phs
            .iter()
            .zip(cpu.world(w).unwrap().pheromones())
            .enumerate()
        {
            let err = relative_error(&g.model, &c.model);
            assert!(
                err <= 1e-5,
                "world {w}, pheromone {k}: relative error {err:e}"
            );
            if let FieldModel::Grid(c) = &c.model {
                nonzero += c.values().iter().filter(|&&v| v > 0.0).count();
            }
        }
    }
    assert!(nonzero > 0, "the fields are empty");
}

#[test]
fn trail_next_step_autoreset_equals_the_cpu() {
    let Some((mut gpu, mut cpu)) = gpu_and_cpu(cfg("trail", None, 5, BackendChoice::Gpu)) else {
        return;
    };
    let ends = lockstep(&mut gpu, &mut cpu, 18, &[]);
    assert!(ends >= 5, "every world ended an episode ({ends} ends)");
    fields_agree(&mut gpu, &cpu);
}

#[test]
fn trail_same_step_autoreset_and_partial_resets_equal_the_cpu() {
    let mut c = cfg("trail", None, 4, BackendChoice::Gpu);
    c.autoreset = AutoresetMode::SameStep;
    let Some((mut gpu, mut cpu)) = gpu_and_cpu(c) else {
        return;
    };
    let resets = [
        (3, vec![false, true, false, true]),
        (9, vec![true, false, false, false]),
    ];
    let ends = lockstep(&mut gpu, &mut cpu, 16, &resets);
    assert!(ends >= 4, "{ends} ends");
    fields_agree(&mut gpu, &cpu);
}

#[test]
fn foraging_equals_the_cpu() {
    let Some((mut gpu, mut cpu)) = gpu_and_cpu(cfg("foraging", None, 3, BackendChoice::Gpu)) else {
        return;
    };
    lockstep(&mut gpu, &mut cpu, 12, &[]);
    fields_agree(&mut gpu, &cpu);
}

/// Agents lay a diffusing red trail by action (no scripted rule), the implicit solver's path.
#[test]
fn deposit_actions_with_diffusion_equal_the_cpu() {
    let action = r#"deposit_actions = [{ pheromone = "red", kernel = { shape = "disc", radius = 0.008 }, max_rate = 6.0 }]"#;
    assert!(TRAIL.contains(SCRIPTED), "the trail scenario changed");
    let text = TRAIL.replace(SCRIPTED, action).replace(
        "evaporation = 20.0\n",
        "evaporation = 20.0\ndiffusion = 2e-5\n",
    );
    assert!(text.contains("diffusion = 2e-5"));
    let mut c = cfg("trail", Some(text), 3, BackendChoice::Gpu);
    c.action = ActionKind::Continuous;
    c.max_cycles = 9;
    let Some((mut gpu, mut cpu)) = gpu_and_cpu(c) else {
        return;
    };
    assert_eq!(gpu.spec().action.flat_len(), 3, "2 wheels + 1 deposit rate");
    lockstep(&mut gpu, &mut cpu, 14, &[(5, vec![false, true, false])]);
    fields_agree(&mut gpu, &cpu);
}

/// `auto` takes the CPU for a small batch whatever the adapter (and says why: the batch's size, or
/// no hardware adapter), and never a software adapter.
#[test]
fn auto_takes_the_cpu_for_small_batches_and_software_adapters() {
    let env = VecEnv::new(&cfg("trail", None, 3, BackendChoice::Auto)).unwrap();
    assert_eq!(env.backend().name(), "cpu");
    let d = env.backend().describe();
    let why = [
        "3 worlds, the GPU pays from 1024",
        "software adapter",
        "no GPU adapter",
    ];
    assert!(why.iter().any(|w| d.contains(w)), "{d}");
}

/// A render draws the batch's fields: the CPU backend's image within one level, where the worlds'
/// own (stale) CPU copies of the fields lack the trails laid since the episode began.
#[test]
fn renders_draw_the_batch_fields() {
    let Some((mut gpu, mut cpu)) = reset_trail_pair(2, 100) else {
        return;
    };
    let ahead = vec![0.7f32; gpu.spec().num_envs * gpu.spec().num_agents * 2];
    for _ in 0..40 {
        gpu.step(Actions::Continuous(&ahead)).unwrap();
        cpu.step(Actions::Continuous(&ahead)).unwrap();
    }
    let agents = gpu.task().agents().to_vec();
    for w in 0..2 {
        let (g, c) = (gpu.render(w, 480).unwrap(), cpu.render(w, 480).unwrap());
        let stale = colcos_env::world_output::render_world(gpu.world(w).unwrap(), &agents, 480);
        let worst = |a: &image::RgbImage| {
            (a.iter().zip(c.iter()))
                .map(|(x, y)| x.abs_diff(*y))
                .max()
                .unwrap()
        };
        assert!(
            worst(&g) <= 1,
            "world {w}: the renders differ by {} levels",
            worst(&g)
        );
        assert!(
            worst(&stale) > 1,
            "world {w}: the trails laid show on the stale copy too"
        );
    }
}

/// A deferred step (a task written in Python) on the GPU batch: the worlds' CPU fields are brought up
/// to date before the task's hooks would read them, and the concluded outputs are the CPU's.
#[test]
fn deferred_steps_see_current_fields_and_conclude_as_the_cpu() {
    let Some((mut gpu, mut cpu)) = reset_trail_pair(3, 6) else {
        return;
    };
    for step in 0..10 {
        let a = actions(&gpu, step);
        cpu.step_deferred(Actions::Continuous(&a)).unwrap();
        gpu.step_deferred(Actions::Continuous(&a)).unwrap();
        for w in 0..3 {
            let (g, c) = (gpu.world(w).unwrap(), cpu.world(w).unwrap());
            for (pg, pc) in g.pheromones().iter().zip(c.pheromones()) {
                let err = relative_error(&pg.model, &pc.model);
                assert!(
                    err <= 1e-5,
                    "step {step}, world {w}: stale fields ({err:e})"
                );
            }
        }
        let (r, t) = (
            vec![0.5; cpu.outputs().rewards().len()],
            vec![false; cpu.outputs().rewards().len()],
        );
        cpu.conclude(&r, &t).unwrap();
        gpu.conclude(&r, &t).unwrap();
        assert_eq!(gpu.outputs().obs(), cpu.outputs().obs(), "step {step}");
        assert_eq!(
            gpu.outputs().truncated(),
            cpu.outputs().truncated(),
            "step {step}"
        );
    }
}
