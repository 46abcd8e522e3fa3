//! A policy on board, on the digital twin: the twin compiles the exported C (bridge/tests/data/onboard,
//! written by scripts/onboard_fixture.py: both wheels at half the largest wheel speed, the left one
//! slowed by the front-left bumper) and runs it on each robot's own readings; the bridge uploads the
//! parameters, starts the policy and sends no wheel commands.
use colcos_bridge::onboard::{
    OnboardFirmware, OnboardManifest, RUNTIME_LEN, RawReadings, robot_params,
};
use colcos_bridge::protocol::colias::colour_from_sim;
use colcos_bridge::protocol::colias::{
    CommandPacket, FrameDecoder, HostCommand, PolicyMode, TELEMETRY_LEN, Telemetry,
};
use colcos_bridge::rig::recorder::read_log;
use colcos_bridge::rig::{self, LiveOptions, LoopCore, replay};
use colcos_bridge::twin::{FIRMWARE_TIMEOUT, Twin};
use colcos_sim::behaviour::WheelCommand;
use colcos_sim::scenario::Scenario;
use colcos_sim::sensors::{ColourCalibration, RobotColour, SensorFit};
use colcos_testkit::scenarios::{onboard, onboard_policy};
use colcos_testkit::twin::{LoopbackTwin, one_at_a_time};
use std::net::UdpSocket;
use std::path::Path;
use std::sync::Arc;
use std::sync::atomic::AtomicBool;

/// Three robots well inside the arena, heading along x; the rig's shield caps the wheels at 0.2 m/s,
/// so the robots' parameter block must say 0.2 (the export says 0.35).
fn scenario(policy: &Path) -> Scenario {
    onboard(policy, 0.3)
}

fn manifest() -> OnboardManifest {
    OnboardManifest::load(&onboard_policy()).unwrap()
}

/// The bridge's live loop and the twin over loopback for `seconds`; `host` is the bridge's scenario
/// (it may name another policy than the twin's robots carry). One run at a time.
fn run(
    host: &Scenario,
    seconds: f64,
) -> (
    Twin,
    rig::LiveReport,
    Vec<colcos_bridge::rig::recorder::Recorded>,
) {
    let _turn = one_at_a_time();
    let mut twin = LoopbackTwin::udp(&scenario(&onboard_policy()), true).spawn(seconds + 0.5);
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("rig.mcap");
    let opts = LiveOptions {
        duration: Some(seconds),
        stream: rig::FrameRate::every_tick(480),
        log: Some(log.clone()),
        ..LiveOptions::default()
    };
    let ends = rig::RigEnds {
        source: twin.pose_source(host),
        link: twin.robot_link(),
        frames: twin.frames.take(),
    };
    let report = rig::run(host, ends, opts, Arc::new(AtomicBool::new(false))).unwrap();
    let twin = twin.join();
    (twin, report, read_log(&std::fs::read(&log).unwrap()))
}

fn commands_to(twin: &Twin, radio: u8) -> Vec<HostCommand> {
    twin.received()
        .iter()
        .filter(|r| r.packet.id == radio)
        .map(|r| r.packet.command)
        .collect()
}

/// The bridge uploads each robot's parameters (the rig's 0.2 m/s limit), starts the policy by its
/// hash and never sends a wheel speed but stops; the robots drive themselves at the policy's half
/// speed (0.1 m/s, straight), report it in telemetry, and the log replays to the same bytes.
#[test]
fn the_twins_robots_run_the_exported_policy_on_board() {
    let m = manifest();
    let host = scenario(&onboard_policy());
    let start: Vec<_> = colcos_sim::world::World::new(&host)
        .unwrap()
        .poses()
        .to_vec();
    let (twin, report, log) = run(&host, 2.5);
    assert!(report.stops.is_empty(), "{report:?}");
    let fleet = twin.onboard().expect("the twin's robots carry the policy");
    for (i, radio) in [1u8, 2, 3].into_iter().enumerate() {
        // Parameters as the host computed them, taken whole by the firmware.
        let expected = robot_params(&m, 0.2, None, radio);
        assert_eq!(expected.len(), RUNTIME_LEN);
        assert_eq!(expected[0], 0.2);
        assert_eq!(
            fleet.params(i),
            expected.as_slice(),
            "robot {radio}'s parameters"
        );
        let sent = commands_to(&twin, radio);
        let writes = sent
            .iter()
            .filter(|c| matches!(c, HostCommand::WriteParamsAt { .. }))
            .count();
        assert_eq!(writes, RUNTIME_LEN.div_ceil(5), "robot {radio}: one upload");
        assert!(sent.contains(&HostCommand::RunPolicy { hash: m.hash }));
        let driven = sent.iter().any(|c| match c {
            HostCommand::WheelSpeeds { left, right } => *left != 0.0 || *right != 0.0,
            HostCommand::Motion { speed, .. } => *speed != 0.0,
            _ => false,
        });
        assert!(!driven, "robot {radio} got a wheel command from the host");
        // Straight along x at 0.1 m/s while the policy ran (~2.5 s less the start).
        let moved = twin.arena().poses()[i].pos - start[i].pos;
        assert!(
            (0.12..0.26).contains(&moved.x) && moved.y.abs() < 0.01,
            "robot {radio} moved {moved:?}"
        );
    }
    // Telemetry said so: running, this hash, 0.1 m/s on both wheels.
    let mut decoder = FrameDecoder::<TELEMETRY_LEN>::new();
    let mut payloads = Vec::new();
    for m in log
        .iter()
        .filter(|m| m.topic == colcos_bridge::rig::recorder::Topic::Telemetry)
    {
        decoder.feed_into(&m.data, &mut payloads);
    }
    let running: Vec<_> = payloads
        .iter()
        .map(|p| Telemetry::decode(p).onboard())
        .filter(|s| s.mode == PolicyMode::Running)
        .collect();
    assert!(running.len() >= 5, "{} running reports", running.len());
    for s in &running {
        assert_eq!(s.hash, m.hash);
        assert_eq!(s.writes_accepted, 12);
        assert_eq!(s.writes_refused, 0);
        assert!(
            (s.left - 0.1).abs() < 1e-6 && (s.right - 0.1).abs() < 1e-6,
            "{s:?}"
        );
    }
    // The exit stop took every robot back from its policy.
    for i in 0..3 {
        assert!(!fleet.running(i));
        assert_eq!(twin.arena().command(i), WheelCommand::STOP);
    }
    // The same poses and telemetry through a fresh loop give the same frames.
    let ticks = replay::ticks_of(&log, 3).unwrap();
    let same = replay::replay(
        &mut LoopCore::new(&host, Default::default()).unwrap(),
        &ticks,
    );
    assert_eq!(same.mismatched_ticks, 0, "{same:?}");
}

/// A bridge that expects another policy than the robots carry: they refuse it, the bridge says which
/// robot and what it carries, holds them stopped, and nothing moves.
#[test]
fn robots_flashed_with_another_policy_are_held() {
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(onboard_policy()).unwrap();
    let other_hash = manifest().hash ^ 1;
    let json = text.replace(
        &format!("\"hash\": {}", manifest().hash),
        &format!("\"hash\": {other_hash}"),
    );
    assert_ne!(json, text);
    std::fs::write(dir.path().join("policy.json"), json).unwrap();
    let host = scenario(&dir.path().join("policy.json"));
    let start: Vec<_> = colcos_sim::world::World::new(&host)
        .unwrap()
        .poses()
        .to_vec();
    let (twin, _report, log) = run(&host, 1.5);
    let events: Vec<String> = log
        .iter()
        .filter(|m| m.topic == colcos_bridge::rig::recorder::Topic::Events)
        .map(|m| String::from_utf8_lossy(&m.data).into_owned())
        .filter(|e| e.contains("onboard_policy_refused"))
        .collect();
    assert_eq!(events.len(), 3, "{events:?}");
    assert!(
        events[0].contains(&format!("{other_hash:#010x}")),
        "{events:?}"
    );
    for (i, s) in start.iter().enumerate() {
        let moved = twin.arena().poses()[i].pos.distance(s.pos);
        assert!(moved < 1e-4, "robot {i} moved {moved} m");
    }
}

/// The twin's robots without a bridge: frames by hand over UDP, the twin stepped by hand.
struct Bench {
    twin: Twin,
    host: UdpSocket,
    decoder: FrameDecoder<TELEMETRY_LEN>,
}

impl Bench {
    fn new() -> Bench {
        let twin = LoopbackTwin::udp(&scenario(&onboard_policy()), false);
        let host = UdpSocket::bind("127.0.0.1:0").unwrap();
        host.connect(twin.link_url.strip_prefix("udp://").unwrap())
            .unwrap();
        let twin = twin.twin;
        host.set_read_timeout(Some(std::time::Duration::from_millis(500)))
            .unwrap();
        Bench {
            twin,
            host,
            decoder: FrameDecoder::new(),
        }
    }
    fn send(&mut self, radio: u8, cmd: HostCommand) {
        self.host
            .send(&CommandPacket::new(radio, 0, cmd).to_frame())
            .unwrap();
        // Loopback delivery is not instant: wait until the twin has it.
        let before = self.twin.received().len();
        for _ in 0..200 {
            self.twin.tick();
            if self.twin.received().len() > before {
                return;
            }
            std::thread::sleep(std::time::Duration::from_millis(1));
        }
        panic!("the twin never received {cmd:?}");
    }
    fn steps(&mut self, n: usize) {
        for _ in 0..n {
            self.twin.tick();
        }
    }
    fn status(&mut self, radio: u8) -> colcos_bridge::protocol::colias::OnboardStatus {
        self.send(radio, HostCommand::RequestTelemetry(1));
        let mut buf = [0u8; 256];
        let mut out = Vec::new();
        while out.is_empty() {
            let k = self.host.recv(&mut buf).unwrap();
            self.decoder.feed_into(&buf[..k], &mut out);
        }
        Telemetry::decode(&out[0]).onboard()
    }
}

/// Refused writes are counted and change nothing; a stop overrides the policy; link silence stops
/// the robot within the firmware's timeout; `PRN` with another hash is refused.
#[test]
fn the_robots_firmware_obeys_stops_and_silence() {
    let m = manifest();
    let mut b = Bench::new();
    // Out of the block, and a zero scale: refused.
    let bad_range = HostCommand::WriteParamsAt {
        offset: (RUNTIME_LEN - 2) as u16,
        count: 5,
        values: [1.0; 5],
    };
    let zero_span = HostCommand::WriteParamsAt {
        offset: 2,
        count: 1,
        values: [0.0; 5],
    };
    b.send(1, bad_range);
    b.send(1, zero_span);
    let s = b.status(1);
    assert_eq!(
        (s.mode, s.writes_accepted, s.writes_refused),
        (PolicyMode::Host, 0, 2)
    );
    assert_eq!(s.hash, m.hash);
    assert_eq!(
        b.twin.onboard().unwrap().params(0),
        m.runtime_defaults.as_slice()
    );
    // Another hash: refused, no motion.
    b.send(1, HostCommand::RunPolicy { hash: m.hash ^ 4 });
    b.steps(10);
    assert_eq!(b.status(1).mode, PolicyMode::Refused);
    assert_eq!(b.twin.arena().command(0), WheelCommand::STOP);
    // The right one: half the export's 0.35 m/s.
    b.send(1, HostCommand::RunPolicy { hash: m.hash });
    b.steps(5);
    let s = b.status(1);
    assert_eq!(s.mode, PolicyMode::Running);
    assert!((s.left - 0.175).abs() < 1e-6, "{s:?}");
    // A stop from the host wins.
    b.send(
        1,
        HostCommand::WheelSpeeds {
            left: 0.0,
            right: 0.0,
        },
    );
    b.steps(5);
    assert_eq!(b.status(1).mode, PolicyMode::Host);
    assert_eq!(b.twin.arena().command(0), WheelCommand::STOP);
    // Started again, then silence: stopped by the firmware within its timeout (+ a tick).
    b.send(1, HostCommand::RunPolicy { hash: m.hash });
    b.steps(3);
    assert_ne!(b.twin.arena().command(0), WheelCommand::STOP);
    let dt = b.twin.arena().world().dt() as f64;
    let silent_steps = (FIRMWARE_TIMEOUT / dt).ceil() as usize + 2;
    b.steps(silent_steps);
    assert_eq!(b.twin.arena().command(0), WheelCommand::STOP);
    assert_eq!(b.status(1).mode, PolicyMode::Host);
    // The other robots never heard a thing.
    assert_eq!(b.twin.arena().command(1), WheelCommand::STOP);
}

/// A manifest that does not fit is refused naming `rig.onboard` and the field.
#[test]
fn bad_manifests_are_refused_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(onboard_policy()).unwrap();
    for (from, to, says) in [
        (
            "colcos-onboard-policy/1",
            "colcos-onboard-policy/9",
            "`format`",
        ),
        (
            "\"prefix\": \"twin_policy\"",
            "\"prefix\": \"9x\"",
            "`prefix`",
        ),
        ("3000.0", "-3000.0", "`runtime_defaults[2]`"),
    ] {
        let path = dir.path().join("policy.json");
        std::fs::write(&path, text.replacen(from, to, 1)).unwrap();
        let err = OnboardManifest::load(&path).unwrap_err().to_string();
        assert!(err.contains("rig.onboard") && err.contains(says), "{err}");
    }
    let big = dir.path().join("big.json");
    std::fs::File::create(&big)
        .unwrap()
        .set_len(64 << 20)
        .unwrap();
    let err = OnboardManifest::load(&big).unwrap_err().to_string();
    assert!(
        err.contains("rig.onboard") && err.contains("67108864 bytes"),
        "{err}"
    );
    let err = OnboardManifest::load(&dir.path().join("missing.json"))
        .unwrap_err()
        .to_string();
    assert!(err.contains("rig.onboard"), "{err}");
    // The C missing beside a good manifest: the twin says so.
    std::fs::write(dir.path().join("policy.json"), &text).unwrap();
    let sc = scenario(&dir.path().join("policy.json"));
    let err = LoopbackTwin::try_udp(&sc, false)
        .err()
        .expect("no C source")
        .to_string();
    assert!(
        err.contains("rig.onboard") && err.contains("C source"),
        "{err}"
    );
}

/// A robot's own four sensors, written into its block from the colour calibration, let the firmware's
/// encoding read the screen's intensities from that robot's raw counts; the export's nominal sensor
/// model would not.
#[test]
fn a_robots_calibration_on_board_recovers_the_screen() {
    let m = manifest();
    let fw = OnboardFirmware::build(&m).unwrap();
    let fits: [SensorFit; 4] = std::array::from_fn(|s| {
        let x = 0.04 * s as f64;
        SensorFit::from_parts(
            1.8 + 0.1 * s as f64,
            1200.0 + 150.0 * s as f64,
            [
                [1.0, 0.1 + x, 0.02],
                [0.05, 1.0, 0.12 - x],
                [0.03, 0.1, 1.0],
            ],
            [20.0 + 5.0 * s as f64, 25.0, 31.0],
            24.0,
        )
    });
    let cal = ColourCalibration::new(
        "2026-01-01T00:00:00Z".into(),
        24.0,
        vec![RobotColour {
            radio_id: 1,
            sensors: fits,
        }],
        0.0,
    );
    let own = robot_params(&m, 0.35, Some(&cal), 1);
    let (mut worst_own, mut worst_nominal) = (0.0f64, 0.0f64);
    for r in (40..=255).step_by(43) {
        for g in (40..=255).step_by(43) {
            for b in (40..=255).step_by(43) {
                let levels = [r as f64, g as f64, b as f64];
                let sim: [[u16; 3]; 4] =
                    std::array::from_fn(|s| fits[s].predict(levels).map(|v| v.round() as u16));
                let colour = colour_from_sim(sim);
                for (params, worst) in [
                    (&own, &mut worst_own),
                    (&m.runtime_defaults, &mut worst_nominal),
                ] {
                    let raw = RawReadings {
                        colour,
                        ir_on: [100; 3],
                        ir_off: [100; 3],
                    };
                    let obs = fw.encode(params, &raw, (0.0, 0.0));
                    for s in 0..4 {
                        for c in 0..3 {
                            let err = (obs[3 * s + c] as f64 - levels[c] / 255.0).abs();
                            *worst = worst.max(err);
                        }
                    }
                }
            }
        }
    }
    eprintln!(
        "largest intensity error: own calibration {worst_own:.2e}, nominal {worst_nominal:.2e}"
    );
    assert!(worst_own < 2e-4, "{worst_own}");
    assert!(worst_nominal > 0.03, "{worst_nominal}");
}
