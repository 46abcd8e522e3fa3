//! The tasks whose agents lay pheromone (`colony`, `coverage`, `alarm`): their rewards as
//! docs/tasks.md writes them out, their per-episode memory, determinism across thread counts, bad
//! parameters refused by name, and each hand-written policy beating random actions.
use colcos_env::baseline::BaselinePolicy;
use colcos_env::task::colony::Layout;
use colcos_env::task::coverage::Coverage;
use colcos_env::task::registry;
use colcos_env::{Actions, EnvConfig, ScenarioSource, VecEnv, policy};
use rand::{RngExt, SeedableRng, rngs::SmallRng};
use serde_json::json;

const COLONY: &str = include_str!("../scenarios/colony.toml");
const COVERAGE: &str = include_str!("../scenarios/coverage.toml");
const ALARM: &str = include_str!("../scenarios/alarm.toml");

/// `text` with its first `[[robots]]` group's count and random placement replaced by explicit poses.
fn placed(text: &str, group: &str, poses: &[[f32; 3]]) -> String {
    let pose_list: Vec<String> = poses.iter().map(|p| format!("{p:?}")).collect();
    let to = format!(
        "count = {}\nrole = \"{group}\"\nbehaviour = \"wander\"\nparams = {{ speed = 0.1 }}\n\
         placement = \"explicit\"\nposes = [{}]\n",
        poses.len(),
        pose_list.join(", ")
    );
    let start = text.find("count = ").expect("a robot group");
    let end = start
        + text[start..]
            .find("placement = \"random\"\n")
            .expect("random")
        + 21;
    let end = if text[end..].starts_with("region") {
        end + text[end..].find('\n').unwrap() + 1
    } else {
        end
    };
    format!("{}{}{}", &text[..start], to, &text[end..])
}

fn env_of(task: &str, text: String, params: serde_json::Value) -> VecEnv {
    let mut cfg = EnvConfig::new(task);
    cfg.scenario = ScenarioSource::Text(text);
    cfg.params = params;
    cfg.max_cycles = 100_000;
    let mut env = VecEnv::new(&cfg).unwrap();
    env.reset(Some(3), None).unwrap();
    env
}

/// Steps `env` (one world) with every agent's action `row`, `steps` times; the rewards of each step.
fn drive(env: &mut VecEnv, rows: &[&[f32]], steps: usize) -> Vec<Vec<f32>> {
    let a: Vec<f32> = rows.iter().flat_map(|r| r.iter().copied()).collect();
    (0..steps)
        .map(|_| {
            env.step(Actions::Continuous(&a)).unwrap();
            env.outputs().rewards().to_vec()
        })
        .collect()
}

#[test]
fn a_delivery_pays_the_whole_team_exactly_and_the_food_runs_out() {
    // Agent 0 on the patch at (0.5, 0.4) facing the nest 12 cm east; agent 1 still, far away.
    let text = placed(COLONY, "agent", &[[0.5, 0.4, 0.0], [1.2, 0.7, 0.0]]);
    let params = json!({ "nest": [0.62, 0.4], "nest_radius": 0.03, "food": [[0.5, 0.4]],
                         "food_radius": 0.03, "food_amount": 2, "delivery_reward": 1.5 });
    let mut env = env_of("colony", text, params);
    assert_eq!(env.obs_dim(), 18);
    let layout = Layout {
        patches: 1,
        agents: 2,
    };
    let (still, ahead, back) = ([0.0; 4], [0.5, 0.5, 0.0, 0.0], [-0.5, -0.5, 0.0, 0.0]);
    let mut delivered = Vec::new();
    for trip in 0..3 {
        // To the nest, then back onto the patch.
        let mut there = drive(&mut env, &[&ahead, &still], 1);
        let picked = env.outputs().obs()[17];
        assert_eq!(picked, if trip < 2 { 1.0 } else { 0.0 }, "trip {trip}");
        there.extend(drive(&mut env, &[&ahead, &still], 39));
        let carry_seen = env.outputs().obs()[17];
        assert_eq!(carry_seen, 0.0, "trip {trip}: dropped at the nest");
        for (t, r) in there.iter().enumerate() {
            assert_eq!(r[0], r[1], "a team reward: step {t}");
            assert!(
                r[0] == 0.0 || r[0] == 1.5,
                "one delivery pays 1.5, got {r:?}"
            );
        }
        delivered.push(there.iter().filter(|r| r[0] == 1.5).count());
        drive(&mut env, &[&back, &still], 40);
    }
    // Two units, two deliveries; the third trip finds the patch empty.
    assert_eq!(delivered, [1, 1, 0]);
    let state = env.task_state(0);
    assert_eq!(layout.food_left(state, 0), 0);
    assert_eq!(layout.delivered(state), 2);
    assert!(!layout.carrying(state, 0));
}

#[test]
fn coverage_pays_each_cell_once_per_episode() {
    let text = placed(COVERAGE, "agent", &[[0.225, 0.425, 0.0]]);
    let mut env = env_of("coverage", text, json!({}));
    // Spinning in place: the start cell pays once, at the first step.
    let spin = drive(&mut env, &[&[-0.3, 0.3, 1.0]], 50);
    assert_eq!(spin[0], [1.0]);
    assert!(spin[1..].iter().all(|r| r[0] == 0.0));
    // Ahead, east, and back over the same cells: each pays once.
    let (ahead, back) = (
        drive(&mut env, &[&[0.5, 0.5, 1.0]], 60),
        drive(&mut env, &[&[-0.5, -0.5, 1.0]], 60),
    );
    let paid: f32 = ahead.iter().flatten().sum();
    assert!(paid >= 3.0, "crossed {paid} new cells");
    assert!(back.iter().flatten().all(|&r| r == 0.0), "cells paid twice");
    let task = Coverage::new(
        &registry::build("coverage", &ScenarioSource::Default, &json!({}))
            .unwrap()
            .1,
        &json!({}),
    )
    .unwrap();
    assert_eq!(task.covered(env.task_state(0)) as f32, 1.0 + paid);
    // A new episode starts its count again.
    env.reset(None, None).unwrap();
    assert_eq!(drive(&mut env, &[&[0.0, 0.0, 0.0]], 1)[0], [1.0]);
}

#[test]
fn alarm_pays_the_safe_fraction_and_flags_the_predator() {
    // Agent 0 5 cm from the predator, agent 1 far away; the predator comes last in the scenario.
    let text = placed(ALARM, "agent", &[[0.7, 0.4, 90.0], [0.2, 0.2, 0.0]]);
    let text = text.replace(
        "params = { speed = 0.2 }\nplacement = \"random\"",
        "params = { speed = 0.0 }\nplacement = \"explicit\"\nposes = [[0.75, 0.4, 0.0]]",
    );
    let mut env = env_of("alarm", text, json!({ "capture_penalty": 2.0 }));
    assert_eq!(env.obs_dim(), 18);
    let r = &drive(&mut env, &[&[0.0, 0.0, 1.0], &[0.0, 0.0, 0.0]], 1)[0];
    assert_eq!(r, &[0.5 - 2.0, 0.5]);
    assert_eq!(
        (env.outputs().obs()[17], env.outputs().obs()[18 + 17]),
        (1.0, 0.0)
    );
}

#[test]
fn bad_parameters_are_refused_by_name() {
    let err = |task: &str, params: serde_json::Value| {
        registry::build(task, &ScenarioSource::Default, &params)
            .err()
            .expect("refused")
            .to_string()
    };
    for (task, params, key) in [
        ("colony", json!({ "food_amount": 0 }), "colony.food_amount"),
        ("colony", json!({ "food": [] }), "colony.food"),
        ("colony", json!({ "food": [[9.0, 0.1]] }), "colony.food[0]"),
        (
            "colony",
            json!({ "nest_radius": -1.0 }),
            "colony.nest_radius",
        ),
        ("colony", json!({ "carry": 2 }), "colony"),
        ("coverage", json!({ "cell": 0.0 }), "coverage.cell"),
        ("coverage", json!({ "cell": 0.0001 }), "coverage.cell"),
        (
            "alarm",
            json!({ "predator_role": "owl" }),
            "alarm.predator_role",
        ),
        (
            "alarm",
            json!({ "predator_role": "agent" }),
            "alarm.predator_role",
        ),
        (
            "alarm",
            json!({ "sense_distance": "far" }),
            "alarm.sense_distance",
        ),
    ] {
        let e = err(task, params.clone());
        assert!(e.contains(key), "{params} -> {e}");
    }
}

/// Every output of `steps` steps of the task's own policy over 4 worlds on `threads` threads.
fn run(task: &str, threads: usize, steps: usize) -> Vec<u32> {
    let mut cfg = EnvConfig::new(task);
    cfg.num_envs = 4;
    cfg.num_threads = Some(threads);
    cfg.max_cycles = 150;
    let mut env = VecEnv::new(&cfg).unwrap();
    env.reset(Some(11), None).unwrap();
    let name = policy::for_task(task).unwrap();
    let mut b = BaselinePolicy::new(&env, name, &serde_json::Value::Null, 5).unwrap();
    let mut a = vec![0.0; 4 * env.spec().num_agents * b.width()];
    let mut out = Vec::new();
    for _ in 0..steps {
        b.act(&env, &mut a).unwrap();
        env.step(Actions::Continuous(&a)).unwrap();
        out.extend(
            env.outputs()
                .obs()
                .iter()
                .chain(env.outputs().rewards())
                .map(|v| v.to_bits()),
        );
        out.extend((0..4).flat_map(|w| env.task_state(w).to_vec()));
    }
    out
}

#[test]
fn one_or_two_threads_give_the_same_episodes() {
    for task in ["colony", "coverage", "alarm"] {
        assert!(run(task, 1, 320) == run(task, 2, 320), "{task}");
    }
}

/// Mean episode return per agent of 4 worlds' first episodes after `reset(seed)`.
fn mean_return(task: &str, seed: u64, hand: bool) -> f64 {
    let mut cfg = EnvConfig::new(task);
    cfg.num_envs = 4;
    let mut env = VecEnv::new(&cfg).unwrap();
    env.reset(Some(seed), None).unwrap();
    let (n, steps) = (env.spec().num_agents, env.spec().max_cycles);
    let name = policy::for_task(task).unwrap();
    let mut b = BaselinePolicy::new(&env, name, &serde_json::Value::Null, seed).unwrap();
    let width = b.width();
    let mut a = vec![0.0; 4 * n * width];
    let mut rng = SmallRng::seed_from_u64(seed);
    let mut total = 0.0f64;
    for _ in 0..steps {
        if hand {
            b.act(&env, &mut a).unwrap();
        } else {
            for (j, v) in a.iter_mut().enumerate() {
                let lo = if j % width < 2 { -1.0 } else { 0.0 };
                *v = rng.random_range(lo..1.0);
            }
        }
        env.step(Actions::Continuous(&a)).unwrap();
        total += env
            .outputs()
            .rewards()
            .iter()
            .map(|&r| r as f64)
            .sum::<f64>();
    }
    total / (4 * n) as f64
}

#[test]
fn each_hand_written_policy_beats_random_actions() {
    for task in ["colony", "coverage", "alarm"] {
        for seed in [1, 2] {
            let (hand, random) = (
                mean_return(task, seed, true),
                mean_return(task, seed, false),
            );
            assert!(
                hand > random,
                "{task}, seed {seed}: {hand} vs random {random}"
            );
        }
    }
}

#[test]
fn the_new_tasks_are_listed_with_their_spaces() {
    let names: Vec<&str> = registry::list().map(|(n, _)| n).collect();
    for (task, obs, act) in [("colony", 18, 4), ("coverage", 17, 3), ("alarm", 18, 3)] {
        assert!(names.contains(&task));
        let env = VecEnv::new(&EnvConfig::new(task)).unwrap();
        let (low, high) = env.spec().observation_bounds();
        assert_eq!((low.len(), high.len()), (obs, obs), "{task}");
        assert_eq!(env.action_decoder().width(), act, "{task}");
        if obs == 18 {
            assert_eq!((low[17], high[17]), (0.0, 1.0));
        }
    }
}
