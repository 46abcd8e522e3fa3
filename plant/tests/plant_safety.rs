//! A plant's safety edges: once closed it never drives again, and a tracker that cannot be reached is
//! named (its URL and the reason) within seconds instead of an episode of made-up poses.
use colcos_env::{Actions, EnvConfig};
use colcos_plant::{LiveEnv, PlantError, PlantKind, PlantOptions};
use std::time::Instant;

fn config() -> EnvConfig {
    let mut cfg = EnvConfig::new("aggregation");
    cfg.max_cycles = 50;
    cfg
}

/// A loopback port with nothing listening on it (TCP and UDP).
fn dead_port() -> u16 {
    let l = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    l.local_addr().unwrap().port()
}

#[test]
fn a_closed_twin_plant_refuses_to_step_or_reset_and_reports_its_stop() {
    let mut opts = PlantOptions::new(PlantKind::Twin);
    opts.goto = false;
    let mut env = LiveEnv::new(&config(), &opts).unwrap();
    env.reset(Some(1)).unwrap();
    // The first observation is of tracked poses, not of (0, 0, 0).
    let host = env.host();
    assert!(host.tracked().iter().all(|p| p.seen));
    let n = env.spec().num_agents;
    env.step(Actions::Continuous(&vec![0.5; 2 * n])).unwrap();
    env.close("test over");
    assert!(env.is_closed());
    for attempt in [
        env.step(Actions::Continuous(&vec![0.5; 2 * n])),
        env.reset(None),
        env.step(Actions::Continuous(&vec![0.5; 2 * n])),
    ] {
        match attempt {
            Err(PlantError::State(msg)) => assert!(msg.contains("closed"), "{msg}"),
            other => panic!("a closed plant must refuse, got {other:?}"),
        }
    }
    let report = env.live_report().expect("the report as it was when closed");
    assert!(
        report.stops.iter().any(|s| s == "shutdown"),
        "{:?}",
        report.stops
    );
    // Closing again is harmless.
    env.close("again");
}

#[test]
fn a_twin_plant_whose_tracker_is_not_there_names_it_within_seconds() {
    let tracker = format!("swarmcon://127.0.0.1:{}", dead_port());
    let robots = format!("udp://127.0.0.1:{}", dead_port());
    let mut opts = PlantOptions::new(PlantKind::Twin);
    opts.tracker = Some(tracker.clone());
    opts.robots = Some(robots);
    opts.goto = false;
    let mut env = LiveEnv::new(&config(), &opts).unwrap();
    let start = Instant::now();
    let err = env.reset(None).expect_err("no tracker: reset must fail");
    let waited = start.elapsed().as_secs_f64();
    assert!(waited < 8.0, "took {waited:.1} s");
    match err {
        PlantError::Unreachable(msg) => {
            assert!(msg.contains(&tracker), "{msg}");
            assert!(msg.to_lowercase().contains("refused"), "{msg}");
        }
        other => panic!("expected Unreachable, got {other:?}"),
    }
    // And it still refuses to step: nothing was observed.
    assert!(env.step(Actions::Continuous(&[0.0; 6])).is_err());
}

#[test]
fn a_replay_of_another_scenarios_log_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("rig.mcap");
    let mut opts = PlantOptions::new(PlantKind::Twin);
    opts.goto = false;
    opts.log = Some(log.clone());
    let mut env = LiveEnv::new(&config(), &opts).unwrap();
    env.reset(Some(1)).unwrap();
    let n = env.spec().num_agents;
    for _ in 0..5 {
        env.step(Actions::Continuous(&vec![0.2; 2 * n])).unwrap();
    }
    env.close("recorded");
    drop(env);
    let mut replay = PlantOptions::new(PlantKind::Replay);
    replay.log = Some(log);
    // The same task's scenario replays; another task's (4 robots, not 5) is refused by name.
    assert!(LiveEnv::new(&config(), &replay).is_ok());
    let err = LiveEnv::new(&EnvConfig::new("trail"), &replay)
        .err()
        .expect("a log of another scenario must be refused")
        .to_string();
    assert!(err.contains("was recorded with scenario"), "{err}");
    assert!(err.contains("robots"), "{err}");
}
