//! `[rig] compensate` on a twin that differs (`Twin` with hidden per-robot truths), over loopback:
//! robots with the same slow, unequal wheels and the same sensor gain and offset, one of them
//! compensated with its identified values. Driven straight ahead by the bridge, the compensated robot
//! drives as the nominal robot beside them does (straight, as far), the other curves and falls
//! short; on the dark screen the compensated robot's own counts read as the nominal robot's.
use colcos_bridge::rig::{LiveOptions, LiveSession, RigEnds};
use colcos_sim::behaviour::WheelCommand;
use colcos_sim::robot::Pose;
use colcos_sim::scenario::SensorSource;
use colcos_testkit::scenarios::parked;
use colcos_testkit::twin::LoopbackTwin;

const ROBOT: &str = "wheel_scale = [0.8, 0.95]\nsensor_gain = 0.8\nsensor_offset = 100.0\n";

#[test]
fn a_compensated_robot_drives_and_reads_as_the_nominal_one() {
    let dir = tempfile::tempdir().unwrap();
    let truth = format!("[[robot]]\nindex = 0\n{ROBOT}[[robot]]\nindex = 1\n{ROBOT}");
    std::fs::write(dir.path().join("truth.toml"), truth).unwrap();
    std::fs::write(
        dir.path().join("fit.toml"),
        format!("[[robot]]\nindex = 0\n{ROBOT}"),
    )
    .unwrap();
    // Robot 0: compensated; 1: the same robot, not compensated; 2: nominal. All face +y.
    let host = parked(&[[0.3, 0.2, 90.0], [0.7, 0.2, 90.0], [1.1, 0.2, 90.0]])
        .with(|s| {
            s.rig.sensors = SensorSource::Robot;
            s.rig.telemetry_hz = 10.0;
            s.rig.compensate = Some("fit.toml".into());
        })
        .base_dir(dir.path())
        .build()
        .unwrap();
    let twin_sc = host.with_truth(&dir.path().join("truth.toml")).unwrap();

    let seconds = 3.0;
    let twin = LoopbackTwin::udp(&twin_sc, false);
    let start: Vec<Pose> = twin.twin.arena().world().poses().to_vec();
    let twin = twin.spawn(seconds + 1.5);
    let ends = RigEnds {
        source: twin.pose_source(&host),
        link: twin.robot_link(),
        frames: None,
    };
    let live_opts = LiveOptions {
        duration: Some(seconds),
        ..LiveOptions::default()
    };
    let mut session = LiveSession::new(&host, ends, live_opts).unwrap();
    let forward = vec![Some(WheelCommand::new(0.04, 0.04)); 3];
    // Each robot's mean count over the ticks after its first answers, all on the black screen (the
    // sensors' noise is about 10 counts a reading).
    let (mut dark, mut ticks) = ([0f64; 3], 0);
    while !session.is_over() {
        session.tick(&forward).unwrap();
        if session.elapsed() > 1.0 {
            let obs = session.core().host().observations();
            for (d, o) in dark.iter_mut().zip(obs) {
                *d += o.counts.iter().flatten().map(|&c| c as f64).sum::<f64>() / 12.0;
            }
            ticks += 1;
        }
        session.wait_next();
    }
    session.stop_all("test over");
    drop(session);
    let end = twin.join().arena().world().poses().to_vec();

    let moved = |i: usize| (end[i].pos - start[i].pos).length();
    let turned = |i: usize| (end[i].heading - start[i].heading).abs();
    let (d0, d1, d2) = (moved(0), moved(1), moved(2));
    println!(
        "moved {d0:.4} {d1:.4} {d2:.4} m, turned {:.3} {:.3} {:.3} rad",
        turned(0),
        turned(1),
        turned(2)
    );
    assert!(d2 > 0.08, "the nominal robot drove {d2} m");
    assert!(
        (d0 / d2 - 1.0).abs() < 0.05,
        "compensated {d0} m against nominal {d2} m"
    );
    assert!(
        d1 / d2 < 0.93,
        "uncompensated {d1} m against nominal {d2} m"
    );
    assert!(
        turned(0) < 0.05 && turned(2) < 0.05,
        "{} {}",
        turned(0),
        turned(2)
    );
    assert!(
        turned(1) > 0.2,
        "the uncompensated robot's unequal wheels turn it: {}",
        turned(1)
    );

    assert!(ticks > 50, "{ticks} ticks after the first second");
    let [c0, c1, c2] = dark.map(|d| d / ticks as f64);
    println!("mean dark counts: compensated {c0:.1}, uncompensated {c1:.1}, nominal {c2:.1}");
    assert!(
        (c0 - c2).abs() < 6.0,
        "compensated {c0} against nominal {c2}"
    );
    assert!(
        c1 > c2 + 80.0,
        "uncompensated {c1} against nominal {c2}: gain 0.8, offset 100"
    );
}
