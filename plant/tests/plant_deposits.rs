//! Pheromone actions on the twin: what the agents choose to lay is laid by the host at their tracked
//! poses, into the field it shows (and streams to the twin's robots), and nothing when they choose 0.
use colcos_env::{Actions, EnvConfig, ScenarioSource};
use colcos_plant::{LiveEnv, PlantKind, PlantOptions};
use colcos_sim::field::FieldModel;

const TRAIL: &str = include_str!("../../env/scenarios/trail.toml");
const SCRIPTED: &str = r#"deposits = [{ pheromone = "red", kernel = { shape = "disc", radius = 0.008 }, rate = 3.0 }]"#;
const CHOSEN: &str = r#"deposit_actions = [{ pheromone = "red", kernel = { shape = "disc", radius = 0.008 }, max_rate = 6.0 }]"#;

/// The red field's total after 40 steps ahead laying at `rate`.
fn red_after(rate: f32) -> f32 {
    assert!(TRAIL.contains(SCRIPTED), "the trail scenario changed");
    let mut cfg = EnvConfig::new("trail");
    cfg.scenario = ScenarioSource::Text(TRAIL.replace(SCRIPTED, CHOSEN));
    cfg.max_cycles = 100;
    let mut opts = PlantOptions::new(PlantKind::Twin);
    opts.goto = false;
    let mut env = LiveEnv::new(&cfg, &opts).unwrap();
    assert_eq!(env.spec().action.flat_len(), 3);
    env.reset(Some(2)).unwrap();
    let n = env.spec().num_agents;
    let a: Vec<f32> = (0..n).flat_map(|_| [0.5, 0.5, rate]).collect();
    for _ in 0..40 {
        env.step(Actions::Continuous(&a)).unwrap();
    }
    let red = &env.host().pheromones()[0];
    assert_eq!(red.name, "red");
    match &red.model {
        FieldModel::Grid(g) => g.values().iter().sum(),
        _ => panic!("red is a grid pheromone"),
    }
}

#[test]
fn the_twins_host_lays_what_the_agents_choose() {
    let laid = red_after(1.0);
    assert!(laid > 1.0, "laid {laid}");
    assert_eq!(red_after(0.0), 0.0);
}
