//! The RL plants over loopback: the digital twin started in-process and a recorded run replayed, with
//! the spaces and outputs of the simulated environment, and the shield keeping a policy that drives at
//! the walls inside the arena.
mod common;

use colcos_env::{Actions, VecEnv};
use colcos_plant::{LiveEnv, PlantKind, PlantOptions, TwinScenario};
use colcos_sim::world::ArenaView;
use common::{config, twin_at_rest};

/// The twins of these tests run in real time, and one of them measures a latency in ticks: one test
/// at a time, so that the others do not take its cores.
static REAL_TIME: std::sync::Mutex<()> = std::sync::Mutex::new(());

fn one_at_a_time() -> std::sync::MutexGuard<'static, ()> {
    REAL_TIME.lock().unwrap_or_else(|e| e.into_inner())
}

/// Every agent drives full speed ahead: on its way to a wall within a few seconds.
fn full_ahead(n: usize) -> Vec<f32> {
    vec![1.0; 2 * n]
}

#[test]
fn the_twin_plant_keeps_a_wall_seeking_policy_inside_and_replays_its_log() {
    let _alone = one_at_a_time();
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("rig.mcap");
    let cfg = config();
    let mut opts = PlantOptions::new(PlantKind::Twin);
    opts.log = Some(log.clone());
    let mut env = LiveEnv::new(&cfg, &opts).unwrap();
    // The same spaces and sizes as the simulated environment.
    let sim = VecEnv::new(&cfg).unwrap();
    let (a, b) = (env.spec(), sim.spec());
    assert_eq!(
        (
            &a.observation,
            &a.action,
            &a.state,
            a.num_agents,
            a.max_cycles
        ),
        (
            &b.observation,
            &b.action,
            &b.state,
            b.num_agents,
            b.max_cycles
        )
    );
    env.reset(Some(3)).unwrap();
    let goto = env.goto_report();
    assert_eq!(goto.arrived, goto.robots, "{goto:?}");
    let n = env.spec().num_agents;
    let arena = env.scenario().arena_size();
    let r = env.scenario().spec.robot.radius;
    let (mut walled, mut steps) = (0, 0);
    while !env.outputs().truncated().iter().any(|t| *t) {
        env.step(Actions::Continuous(&full_ahead(n))).unwrap();
        steps += 1;
        walled += env
            .outputs()
            .shield_flags()
            .iter()
            .filter(|f| **f & 2 != 0)
            .count();
        assert!(
            env.outputs()
                .obs()
                .iter()
                .all(|v| v.is_finite() && (-1.0..=1.0).contains(v))
        );
        for p in ArenaView::poses(env.host()) {
            assert!(
                p.pos.x > r * 0.5 && p.pos.x < arena.x - r * 0.5,
                "{p:?} left the arena"
            );
            assert!(p.pos.y > r * 0.5 && p.pos.y < arena.y - r * 0.5, "{p:?}");
        }
    }
    assert_eq!(steps, 120);
    assert!(walled > 0, "the shield never turned a robot from a wall");
    let report = env.live_report().unwrap();
    assert!(
        report.shield.walled > 0 && report.stops.is_empty(),
        "{report:?}"
    );
    drop(env);
    // The run's log replayed: the recorded ticks, with the policy's commands again.
    let mut opts = PlantOptions::new(PlantKind::Replay);
    opts.log = Some(log);
    let mut replay = LiveEnv::new(&cfg, &opts).unwrap();
    replay.reset(None).unwrap();
    let mut steps = 0;
    while !replay.outputs().truncated().iter().any(|t| *t) {
        replay.step(Actions::Continuous(&full_ahead(n))).unwrap();
        steps += 1;
    }
    assert!(steps >= 100, "{steps} replayed steps");
}

#[test]
fn a_plant_without_what_it_needs_names_it() {
    let _alone = one_at_a_time();
    let cfg = config();
    let err = |opts: PlantOptions| LiveEnv::new(&cfg, &opts).err().unwrap().to_string();
    assert!(err(PlantOptions::new(PlantKind::Replay)).contains("`replay`"));
    let mut rig = PlantOptions::new(PlantKind::Rig);
    assert!(err(rig.clone()).contains("`tracker`"));
    rig.tracker = Some("swarmcon://127.0.0.1:1".into());
    rig.robots = Some("udp://127.0.0.1:1".into());
    // No robot is driven without a current screen calibration.
    assert!(
        err(rig).contains("`rig.screen_calibration`: the rig plant needs a screen calibration")
    );
    let mut twin = PlantOptions::new(PlantKind::Twin);
    twin.tracker = Some("swarmcon://127.0.0.1:1".into());
    twin.robots = Some("bogus://x".into());
    assert!(err(twin).contains("robot link"));
    let mut replay = PlantOptions::new(PlantKind::Replay);
    replay.log = Some("/nonexistent/rig.mcap".into());
    assert!(err(replay).contains("/nonexistent/rig.mcap"));
    assert!("simulator".parse::<PlantKind>().is_err());
    // Robots that run their own policy would ignore the environment's actions.
    let mut onboard = config();
    let text = include_str!("../../env/scenarios/aggregation.toml");
    onboard.scenario = colcos_env::ScenarioSource::Text(format!(
        "{text}\n[rig]\nonboard = \"firmware/policy.json\"\n"
    ));
    let e = LiveEnv::new(&onboard, &PlantOptions::new(PlantKind::Twin))
        .err()
        .unwrap()
        .to_string();
    assert!(
        e.contains("rig.onboard") && e.contains("colcos bridge"),
        "{e}"
    );
}

/// Steps (20 ms) from the first full-ahead command until the tracker shows the host any agent moved
/// 8 mm (the tracker's noise is 1 mm), on a twin playing `twin` (none: the host's scenario).
fn steps_until_seen_moving(twin: Option<TwinScenario>) -> usize {
    // Still for half a second: every pose the host holds is of robots at rest.
    let (mut env, n) = twin_at_rest(|opts| opts.twin_scenario = twin, 25);
    let start: Vec<_> = env.host().tracked().to_vec();
    // The agents, which the policy drives: a scripted robot wanders on its own.
    let agents = env.spec().agent_robots.clone();
    for k in 1..=60 {
        env.step(Actions::Continuous(&full_ahead(n))).unwrap();
        let tracked = env.host().tracked();
        let moved =
            (agents.iter()).any(|&i| (tracked[i].pose.pos - start[i].pose.pos).length() > 0.008);
        if moved {
            return k;
        }
    }
    panic!("no robot seen moving within 60 steps");
}

#[test]
fn a_twin_with_its_own_tracker_latency_is_seen_later_by_the_host() {
    let _alone = one_at_a_time();
    let own = steps_until_seen_moving(None);
    let late = steps_until_seen_moving(Some(TwinScenario::Overrides(vec![(
        "tracker.latency".into(),
        serde_json::json!(0.2),
    )])));
    // The host's scenario says 40 ms; the twin's tracker holds poses back 200 ms: ~8 ticks later.
    assert!(
        late >= own + 5,
        "seen moving after {own} steps on the host's twin, {late} on the late one"
    );
}

#[test]
fn a_twin_scenario_of_another_arena_or_with_urls_is_refused() {
    let _alone = one_at_a_time();
    let cfg = config();
    let mut opts = PlantOptions::new(PlantKind::Twin);
    opts.twin_scenario = Some(TwinScenario::Overrides(vec![(
        "dt".into(),
        serde_json::json!(0.04),
    )]));
    let err = LiveEnv::new(&cfg, &opts).err().unwrap().to_string();
    assert!(err.contains("`twin_scenario.dt`"), "{err}");
    opts.twin_scenario = Some(TwinScenario::Overrides(vec![]));
    opts.tracker = Some("swarmcon://127.0.0.1:1".into());
    opts.robots = Some("udp://127.0.0.1:1".into());
    let err = LiveEnv::new(&cfg, &opts).err().unwrap().to_string();
    assert!(err.contains("`twin_scenario`"), "{err}");
}
