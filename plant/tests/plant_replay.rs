//! A replay plant plays the recorded episodes one by one: each `reset` starts the next episode at
//! the tick the live plant started it (after its go-to drive), and runs as many steps as were taken;
//! after the last, the first again.
use colcos_env::{Actions, EnvConfig};
use colcos_plant::{LiveEnv, PlantKind, PlantOptions};

#[test]
fn a_replay_plays_the_recorded_episodes_not_the_whole_log() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("rig.mcap");
    let mut cfg = EnvConfig::new("aggregation");
    cfg.max_cycles = 15;
    let mut twin = PlantOptions::new(PlantKind::Twin);
    twin.log = Some(log.clone());
    twin.goto_timeout = 2.0;
    let mut env = LiveEnv::new(&cfg, &twin).unwrap();
    let n = env.spec().num_agents;
    let ahead = vec![0.3; 2 * n];
    // Two episodes of 10 steps each, the second after a go-to drive.
    for episode in 0..2 {
        env.reset(if episode == 0 { Some(4) } else { None })
            .unwrap();
        for _ in 0..10 {
            env.step(Actions::Continuous(&ahead)).unwrap();
        }
    }
    env.close("recorded");
    drop(env);

    let mut replay = PlantOptions::new(PlantKind::Replay);
    replay.log = Some(log);
    let mut env = LiveEnv::new(&cfg, &replay).unwrap();
    for episode in 0..2 {
        env.reset(if episode == 0 { Some(4) } else { None })
            .unwrap();
        let mut steps = 0;
        while !env.outputs().truncated()[0] && !env.outputs().terminated()[0] {
            env.step(Actions::Continuous(&ahead)).unwrap();
            steps += 1;
        }
        assert_eq!(steps, 10, "episode {episode}");
    }
    // After the last recorded episode, the first again.
    env.reset(None).unwrap();
    assert_eq!(env.episode(), 2);
    let first_again = (0..20)
        .take_while(|_| {
            env.step(Actions::Continuous(&ahead)).unwrap();
            !env.outputs().truncated()[0]
        })
        .count();
    assert_eq!(first_again + 1, 10);
}
