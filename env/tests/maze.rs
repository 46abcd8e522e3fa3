//! The `trail` task's `maze` option: the walled corridor is built, agents driven straight stay out of
//! its walls and their bumpers see them; `maze = true` on a scenario without obstacles is refused.
use colcos_env::{Actions, EnvConfig, ScenarioSource, VecEnv};
use colcos_sim::robot::PhysicsBackend;

fn maze_config(physics: PhysicsBackend) -> EnvConfig {
    let mut cfg = EnvConfig::new("trail");
    cfg.params = serde_json::json!({ "maze": true });
    cfg.num_envs = 4;
    cfg.shield = false;
    cfg.physics = Some(physics);
    cfg
}

#[test]
fn agents_driven_straight_meet_the_walls_and_stay_out() {
    for physics in [PhysicsBackend::Discs, PhysicsBackend::Rapier] {
        let mut env = VecEnv::new(&maze_config(physics)).unwrap();
        env.reset(Some(3), None).unwrap();
        let world = env.world(0).unwrap();
        assert!(!world.obstacles().is_empty(), "{physics:?}: no obstacles");
        let n = env.spec().num_agents * 4;
        // Full speed ahead with a slight left turn: the agents leave the loop's curve and hit walls.
        let actions: Vec<f32> = (0..n).flat_map(|_| [1.0, 0.8]).collect();
        let mut bumped = 0.0f32;
        for _ in 0..300 {
            env.step(Actions::Continuous(&actions)).unwrap();
            for e in 0..4 {
                let w = env.world(e).unwrap();
                let r = w.robot_params().radius;
                for (i, p) in w.poses().iter().enumerate() {
                    // rapier's contacts are stiff springs: allow 2 mm.
                    assert!(
                        w.obstacles().overlapping(p.pos, r, 0.002).is_none(),
                        "{physics:?}: world {e} robot {i} at {:?} inside a wall",
                        p.pos
                    );
                }
                for o in w.observations() {
                    bumped = bumped.max(o.max_bumper());
                }
            }
        }
        assert!(
            bumped > 0.5,
            "{physics:?}: the bumpers never saw a wall ({bumped})"
        );
    }
}

#[test]
fn maze_on_a_scenario_without_obstacles_is_refused() {
    let mut cfg = EnvConfig::new("trail");
    cfg.params = serde_json::json!({ "maze": true });
    cfg.scenario = ScenarioSource::Text(colcos_env::task::trail::DEFAULT_SCENARIO.to_string());
    let e = VecEnv::new(&cfg).err().expect("accepted").to_string();
    assert!(
        e.contains("trail.maze") && e.contains("[[obstacles]]"),
        "{e}"
    );
    cfg.params = serde_json::json!({ "maze": "yes" });
    cfg.scenario = ScenarioSource::Default;
    let e = VecEnv::new(&cfg).err().expect("accepted").to_string();
    assert!(e.contains("maze"), "{e}");
}
