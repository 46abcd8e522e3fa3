//! The worlds of a vector env take the field backend from the scenario's `[field] backend` (or
//! `EnvConfig::backend`). With the `gpu` feature (`cargo test -p colcos-env --features gpu`): `gpu`
//! runs on any adapter and gives the CPU's observations, also in worlds rebuilt by autoreset
//! (`gpu_batch.rs` compares more tasks and resets); without it, `gpu` is an error and `auto` the CPU.
#[cfg(feature = "gpu")]
use colcos_env::{Actions, ScenarioSource};
use colcos_env::{EnvConfig, EnvError, VecEnv};
use colcos_sim::field::BackendChoice;

fn cfg(task: &str, backend: Option<BackendChoice>) -> EnvConfig {
    let mut c = EnvConfig::new(task);
    c.num_envs = 3;
    c.max_cycles = 10;
    c.seed = 7;
    c.num_threads = Some(2);
    c.backend = backend;
    c
}

#[test]
fn cpu_is_the_default() {
    let env = VecEnv::new(&cfg("trail", None)).unwrap();
    assert_eq!(env.backend().name(), "cpu");
    assert_eq!(env.backend().describe(), "cpu (asked for)");
}

#[cfg(not(feature = "gpu"))]
#[test]
fn without_the_feature_gpu_is_an_error_and_auto_the_cpu() {
    match VecEnv::new(&cfg("trail", Some(BackendChoice::Gpu))) {
        Err(EnvError::Backend(m)) => assert!(m.contains("`gpu` feature"), "{m}"),
        Err(e) => panic!("unexpected error {e}"),
        Ok(_) => panic!("gpu accepted without the feature"),
    }
    let env = VecEnv::new(&cfg("trail", Some(BackendChoice::Auto))).unwrap();
    assert_eq!(env.backend().name(), "cpu");
}

/// The scenario key works as the config field does.
#[cfg(feature = "gpu")]
#[test]
fn scenario_key_and_gpu_observations() {
    let text = colcos_env::task::registry::default_scenario("trail")
        .unwrap()
        .replace("[field]\n", "[field]\nbackend = \"gpu\"\n");
    assert!(text.contains("backend = \"gpu\""));
    let mut c = cfg("trail", None);
    c.scenario = ScenarioSource::Text(text);
    let mut gpu = match VecEnv::new(&c) {
        Ok(e) => e,
        Err(EnvError::Backend(m)) => {
            if std::env::var("COLCOS_REQUIRE_GPU").is_ok_and(|v| v == "1") {
                panic!("COLCOS_REQUIRE_GPU=1 but {m}");
            }
            eprintln!("skipping: {m}");
            return;
        }
        Err(e) => panic!("{e}"),
    };
    assert_eq!(gpu.backend().name(), "gpu", "{}", gpu.backend().describe());
    // Every world's grids in the environment's GPU batch, none stepping its own.
    assert!(gpu.backend().is_batched(), "{}", gpu.backend().describe());
    assert!(gpu.world(0).unwrap().external_grids());
    assert!(gpu.world(0).unwrap().field_backend().is_none());
    let mut cpu = VecEnv::new(&cfg("trail", Some(BackendChoice::Cpu))).unwrap();
    gpu.reset(None, None).unwrap();
    cpu.reset(None, None).unwrap();
    let n = gpu.spec().num_agents;
    let mut a = vec![0f32; 3 * n * 2];
    for (k, v) in a.iter_mut().enumerate() {
        *v = ((k * 37 % 11) as f32 / 5.0) - 1.0;
    }
    // 12 steps with max_cycles = 10: the worlds are rebuilt (next-step autoreset), on the GPU too.
    for step in 0..12 {
        gpu.step(Actions::Continuous(&a)).unwrap();
        cpu.step(Actions::Continuous(&a)).unwrap();
        let worst = gpu
            .outputs()
            .obs()
            .iter()
            .zip(cpu.outputs().obs())
            .map(|(g, c)| (g - c).abs())
            .fold(0f32, f32::max);
        assert!(worst <= 1e-5, "step {step}: observations differ by {worst}");
    }
    assert!(gpu.world(2).unwrap().external_grids());
    assert_eq!(gpu.world(2).unwrap().time(), cpu.world(2).unwrap().time());
}

#[cfg(feature = "gpu")]
#[test]
fn gaussian_only_task_reports_the_cpu() {
    match VecEnv::new(&cfg("aggregation", Some(BackendChoice::Gpu))) {
        Ok(env) => {
            assert_eq!(env.backend().name(), "cpu");
            assert!(env.backend().describe().contains("no grid pheromones"));
        }
        Err(EnvError::Backend(m)) => eprintln!("skipping: {m}"),
        Err(e) => panic!("{e}"),
    }
}

#[cfg(feature = "gpu")]
#[test]
fn auto_never_takes_a_software_adapter() {
    let env = VecEnv::new(&cfg("trail", Some(BackendChoice::Auto))).unwrap();
    let d = env.backend().describe();
    if env.backend().name() == "gpu" {
        assert!(!d.contains("software"), "{d}");
    } else {
        assert!(d.starts_with("cpu (auto"), "{d}");
    }
}
