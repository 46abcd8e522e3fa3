//! The bridge's live loop driving the digital twin end to end over loopback: SwarmCon over TCP, the
//! robots' serial protocol over UDP and over a pseudo-terminal, the displayed frames over the frame
//! stream; and the safety stops, measured from the twin's own record of what it received.
use colcos_bridge::protocol::colias::{BROADCAST_ID, HostCommand};
use colcos_bridge::rig::recorder::{Topic, read_log};
use colcos_bridge::rig::{self, LiveOptions, LiveReport, LoopCore, replay};
use colcos_bridge::twin::{ByteChannel, PtyChannel, Received, RobotFaults, TrackerFaults, Twin};
use colcos_sim::scenario::Scenario;
use colcos_testkit::twin::{LoopbackTwin, RunningTwin, one_at_a_time, udp_channel};
use std::sync::atomic::AtomicBool;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// These tests time a real-time loop against a real-time twin: run side by side on a 2-core machine
/// they starve each other's tracker streams ("tracker_silent"), so they take turns.
fn one_rig_at_a_time() -> std::sync::MutexGuard<'static, ()> {
    static RIG: Mutex<()> = Mutex::new(());
    RIG.lock().unwrap_or_else(|e| e.into_inner())
}

fn scenario() -> Scenario {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../scenarios/case2_alarm.toml");
    Scenario::from_file(path).unwrap()
}

struct Rig {
    twin: RunningTwin,
    faults: Arc<Mutex<TrackerFaults>>,
    report: LiveReport,
    log: Vec<colcos_bridge::rig::recorder::Recorded>,
    bridge_stopped_at: Instant,
}

/// Runs the twin and the bridge side by side for `seconds`; `during` runs on the test thread
/// meanwhile (to switch faults). The twin keeps running a little after the bridge ends.
fn run_rig(
    sc: Scenario,
    channel: Box<dyn ByteChannel>,
    link_url: String,
    seconds: f64,
    during: impl FnOnce(&Arc<Mutex<TrackerFaults>>, &Arc<Mutex<RobotFaults>>),
) -> Rig {
    let _turn = one_at_a_time();
    let mut twin = LoopbackTwin::over(&sc, channel, link_url, true);
    let faults = twin.twin.tracker().faults();
    let robot_faults = twin.twin.robots().faults.clone();
    let mut twin = twin.spawn(seconds + 1.0);
    let ends = rig::RigEnds {
        source: twin.pose_source(&sc),
        link: twin.robot_link(),
        frames: twin.frames.take(),
    };
    let dir = tempfile::tempdir().unwrap();
    let log_path = dir.path().join("rig.mcap");
    let live_opts = LiveOptions {
        duration: Some(seconds),
        stream: rig::FrameRate::new(480, 25.0),
        log: Some(log_path.clone()),
        trajectory: Some(dir.path().join("trajectory.csv")),
        gif: Some(dir.path().join("run.gif")),
        ..LiveOptions::default()
    };
    let stop = Arc::new(AtomicBool::new(false));
    let bridge = {
        let sc = sc.clone();
        let stop = stop.clone();
        std::thread::spawn(move || rig::run(&sc, ends, live_opts, stop).unwrap())
    };
    during(&faults, &robot_faults);
    let report = bridge.join().unwrap();
    let bridge_stopped_at = Instant::now();
    let log = read_log(&std::fs::read(&log_path).unwrap());
    // The log and the report record the latencies the run ran with.
    let meta = colcos_bridge::rig::recorder::read_metadata(&std::fs::read(&log_path).unwrap());
    let rig_meta = &meta
        .iter()
        .find(|(name, _)| name == "rig")
        .expect("rig metadata")
        .1;
    assert_eq!(rig_meta["rig_latency"], sc.spec.rig.latency.to_string());
    assert_eq!(
        rig_meta["tracker_latency"],
        sc.spec.tracker.latency.to_string()
    );
    assert_eq!(report.tracker_latency, sc.spec.tracker.latency);
    // The trajectory has the simulator's columns and one row per robot and tick from the tracker's
    // first pose on, counted from 0; no robot is ever at the (0, 0) of a pose not yet tracked.
    let csv = std::fs::read_to_string(dir.path().join("trajectory.csv")).unwrap();
    let mut lines = csv.lines();
    assert_eq!(
        lines.next(),
        Some(colcos_sim::output::trajectory::header().as_str())
    );
    let rows: Vec<&str> = lines.collect();
    assert_eq!(rows.len() as u64, 5 * report.logged_ticks);
    assert!(report.logged_ticks > 0 && report.logged_ticks <= report.ticks);
    assert!(rows[0].starts_with("0,"), "{}", rows[0]);
    for row in &rows[..5] {
        let xy: Vec<f64> = row
            .split(',')
            .skip(4)
            .take(2)
            .map(|v| v.parse().unwrap())
            .collect();
        assert!(xy != [0.0, 0.0], "a robot at (0, 0): {row}");
    }
    // The run's GIF, complete when the loop returns: a frame per `gif_interval`.
    let gif = std::fs::read(dir.path().join("run.gif")).unwrap();
    let frames = gif.windows(3).filter(|w| *w == [0x21, 0xF9, 0x04]).count();
    let interval = sc.spec.output.gif_interval as f64;
    assert!(gif.ends_with(&[0x3B]), "the GIF has no trailer");
    assert!(
        frames as f64 >= (report.seconds / interval).floor() - 1.0,
        "{frames} GIF frames in {} s",
        report.seconds
    );
    Rig {
        twin,
        faults,
        report,
        log,
        bridge_stopped_at,
    }
}

/// A 3 s run over UDP whose tracker takes `fault` 1.5 s in, and the moment it did.
fn run_with_tracker_fault(fault: impl FnOnce(&mut TrackerFaults)) -> (Rig, Instant) {
    let (channel, url) = udp_channel();
    let mut at = None;
    let rig = run_rig(scenario(), channel, url, 3.0, |faults, _| {
        std::thread::sleep(Duration::from_millis(1500));
        fault(&mut faults.lock().unwrap());
        at = Some(Instant::now());
    });
    (rig, at.expect("the fault was set"))
}

fn wheel_speeds(p: &HostCommand) -> Option<(f32, f32)> {
    match p {
        HostCommand::WheelSpeeds { left, right } => Some((*left, *right)),
        _ => None,
    }
}

/// The motion commands among `received` (wheel speeds not both zero), with their speeds.
fn motion(received: &[Received]) -> impl Iterator<Item = (&Received, (f32, f32))> {
    received
        .iter()
        .filter_map(|c| Some((c, wheel_speeds(&c.packet.command)?)))
        .filter(|(_, (l, r))| *l != 0.0 || *r != 0.0)
}

/// The first command after `fault_at` that `is_stop` picks, checked to come within `limit` s of the
/// fault. The last fresh pose may be up to a block period (40 ms) older than the fault; 50 ms past
/// the limit is the requirement (0-20 ms measured idle), 100 ms what a loaded CI machine gets.
fn stop_in_time(
    twin: &Twin,
    fault_at: Instant,
    limit: f32,
    is_stop: impl Fn(&Received) -> bool,
) -> &Received {
    let stop = twin
        .received()
        .iter()
        .find(|c| c.at > fault_at && is_stop(c))
        .expect("a stop after the fault");
    let delay = stop.at.duration_since(fault_at).as_secs_f64();
    let limit = limit as f64;
    eprintln!("stop {delay:.3} s after the fault");
    assert!(
        delay <= limit + 0.1,
        "stop {delay:.3} s after the fault (limit {limit} s + 100 ms)"
    );
    stop
}

/// Case II's behaviours on the host drive the twin's five robots over UDP: every robot gets wheel
/// commands and moves, poses and frames flow, the log holds what crossed the wires, and the loop
/// keeps its 20 ms.
#[test]
fn case_two_drives_the_twin_over_udp() {
    let _alone = one_rig_at_a_time();
    let (channel, url) = udp_channel();
    let start_poses: Vec<_> = {
        let sc = scenario();
        colcos_sim::world::World::new(&sc).unwrap().poses().to_vec()
    };
    let rig = run_rig(scenario(), channel, url, 4.0, |_, _| {});
    let twin = rig.twin.join();
    let r = &rig.report;
    assert!(r.ticks >= 150, "{r:?}");
    assert!(r.pose_blocks >= 60, "{r:?}");
    assert!(r.stops.is_empty(), "no safety stop expected: {r:?}");
    assert!(r.telemetry_received >= 10, "{r:?}");
    // Every robot was driven, and moved.
    let received = twin.received();
    for (i, id) in (1..=5u8).enumerate() {
        let moving = motion(received).any(|(c, _)| c.packet.id == id);
        assert!(moving, "robot {id} never got a motion command");
        let moved = twin.arena().poses()[i].pos.distance(start_poses[i].pos);
        assert!(moved > 0.02, "robot {id} moved only {moved} m");
    }
    // S(t) of eq. (9), the followers' summed distance to the leader: the robots on the twin aggregate
    // as in the pure simulation. They differ by the latency the rig adds (tracker 40 ms + a block
    // period + a tick, ~0.1 s of a robot's 8 cm/s) and by their random streams, so only the trend and
    // the rough amount are compared.
    let s_of = |poses: &[colcos_sim::robot::Pose]| {
        let pos: Vec<_> = poses.iter().map(|p| p.pos).collect();
        colcos_sim::metrics::sum_distance_of(&pos, 0, &[1, 2, 3])
    };
    let mut sim = colcos_sim::world::World::new(&scenario()).unwrap();
    // The twin ran on a second after the bridge stopped its robots.
    let steps = (r.seconds / sim.dt() as f64).round() as usize;
    for _ in 0..steps {
        sim.step();
    }
    let (s0, s_sim, s_twin) = (
        s_of(&start_poses),
        s_of(sim.poses()),
        s_of(twin.arena().poses()),
    );
    let (r_sim, r_twin) = (s_sim / s0, s_twin / s0);
    eprintln!(
        "S(t)/S(0) after {:.1} s: simulation {r_sim:.3}, twin {r_twin:.3}",
        r.seconds
    );
    assert!(
        r_twin < 1.0 && r_sim < 1.0,
        "no aggregation: sim {r_sim}, twin {r_twin}"
    );
    assert!((r_sim - r_twin).abs() < 0.15, "sim {r_sim}, twin {r_twin}");
    // The last thing sent is the exit guard's broadcast stop, and the twin's robots obey it.
    let last = received.last().unwrap().packet;
    assert_eq!(last.id, BROADCAST_ID);
    assert_eq!(wheel_speeds(&last.command), Some((0.0, 0.0)));
    for i in 0..5 {
        assert_eq!(
            twin.arena().command(i),
            colcos_sim::behaviour::WheelCommand::STOP
        );
    }
    // The rig log has every kind of traffic, the commands byte for byte as the twin received them.
    let count = |t: Topic| rig.log.iter().filter(|m| m.topic == t).count();
    assert!(
        count(Topic::Poses) >= 60 && count(Topic::Frames) >= 50 && count(Topic::Telemetry) >= 10
    );
    let logged: Vec<&[u8]> = rig
        .log
        .iter()
        .filter(|m| m.topic == Topic::Commands || m.topic == Topic::Stops)
        .map(|m| m.data.as_slice())
        .collect();
    let wire: Vec<Vec<u8>> = received.iter().map(|c| c.packet.to_frame()).collect();
    let missing = wire
        .iter()
        .filter(|w| !logged.contains(&w.as_slice()))
        .count();
    assert_eq!(missing, 0, "commands the twin received that the log lacks");
    // The recorded poses, telemetry and tick times, put through a fresh loop, give the same command
    // bytes; poses moved by 5 cm do not.
    let mut ticks = replay::ticks_of(&rig.log, 5).unwrap();
    assert_eq!(ticks.len() as u64, r.ticks);
    let fresh_core = || LoopCore::new(&scenario(), Default::default()).unwrap();
    let same = replay::replay(&mut fresh_core(), &ticks);
    assert!(same.frames > 200, "{same:?}");
    assert_eq!(same.mismatched_ticks, 0, "{same:?}");
    for tick in ticks.iter_mut().filter(|t| t.t > 1.0) {
        for p in &mut tick.poses {
            p.pose.pos.x += 0.05;
        }
    }
    let moved = replay::replay(&mut fresh_core(), &ticks);
    assert!(moved.mismatched_ticks > 0, "{moved:?}");
    let _ = rig.faults;
}

/// The same loop over a real pseudo-terminal, through the bridge's serial code.
#[test]
fn the_serial_link_drives_the_twin_over_a_pty() {
    let _alone = one_rig_at_a_time();
    let channel = PtyChannel::open().unwrap();
    let url = format!("serial://{}?baud=115200", channel.peer_path());
    let rig = run_rig(scenario(), Box::new(channel), url, 2.0, |_, _| {});
    let twin = rig.twin.join();
    let driven = motion(twin.received()).count();
    assert!(
        driven >= 20,
        "{driven} motion commands over the pty; {:?}",
        rig.report
    );
    assert!(rig.report.telemetry_received >= 3, "{:?}", rig.report);
}

/// Tracker silence: every robot is stopped (a broadcast stop reaches the twin) within the silence
/// limit plus 50 ms, measured on the twin's receipt times.
#[test]
fn tracker_silence_stops_every_robot_in_time() {
    let _alone = one_rig_at_a_time();
    let (rig, silent_at) = run_with_tracker_fault(|f| f.silent = true);
    let twin = rig.twin.join();
    // A broadcast stop, while the bridge still ran.
    let limit = scenario().spec.rig.tracker_silence;
    let stop = stop_in_time(&twin, silent_at, limit, |c| {
        c.packet.id == BROADCAST_ID && rig.bridge_stopped_at > c.at
    });
    assert!(
        rig.report.stops.contains(&"tracker_silent".to_string()),
        "{:?}",
        rig.report
    );
    // While silent, no motion command follows the stop.
    let after: Vec<_> = motion(twin.received())
        .filter(|(c, _)| c.at > stop.at && rig.bridge_stopped_at > c.at)
        .map(|(_, speeds)| speeds)
        .collect();
    assert!(after.is_empty(), "motion after the safety stop: {after:?}");
}

/// Blocks split into 7-byte writes, two blocks per write, garbage lines between them and a tracker
/// clock an hour ahead: the bridge still takes every pose, drives every robot and sends no stop.
#[test]
fn stream_faults_do_not_stop_the_loop() {
    let _alone = one_rig_at_a_time();
    let (channel, url) = udp_channel();
    // Two blocks per write leave gaps of two tracker frames by design, plus the 7-byte writes' own
    // delay: the default silence limit (0.1 s) would stop a slowed machine for a gap this test makes on
    // purpose. `tracker_silence_stops_every_robot_in_time` tests the limit itself.
    let mut sc = scenario();
    sc.spec.rig.tracker_silence = 0.3;
    let rig = run_rig(sc, channel, url, 3.0, |faults, _| {
        let mut f = faults.lock().unwrap();
        f.split = 7;
        f.merge = 2;
        f.garbage = true;
        f.clock_offset_us = 3_600_000_000;
    });
    let twin = rig.twin.join();
    let r = &rig.report;
    assert!(r.stops.is_empty(), "{r:?}");
    assert!(r.pose_blocks >= 30, "{r:?}");
    for id in 1..=5u8 {
        let moving = motion(twin.received()).any(|(c, _)| c.packet.id == id);
        assert!(moving, "robot {id} never got a motion command");
    }
    // Ages on the host clock, not the tracker's: well under a second, despite the hour of offset.
    let ages: Vec<f64> = rig
        .log
        .iter()
        .filter(|m| m.topic == Topic::Poses)
        .flat_map(|m| {
            let v: serde_json::Value = serde_json::from_slice(&m.data).unwrap();
            v.as_array()
                .unwrap()
                .iter()
                .map(|p| p["age"].as_f64().unwrap())
                .collect::<Vec<_>>()
        })
        .collect();
    let worst = ages.iter().copied().fold(0.0, f64::max);
    assert!(worst < 0.5, "a pose {worst} s old");
}

/// A robot the camera loses (its slot goes stale): that robot alone is stopped within the pose-age
/// limit plus 50 ms; the others keep driving.
#[test]
fn a_lost_robot_alone_is_stopped_in_time() {
    let _alone = one_rig_at_a_time();
    let (rig, hidden_at) = run_with_tracker_fault(|f| f.hidden = vec![2]);
    let twin = rig.twin.join();
    // Tracker ID 2 is the third robot, radio address 3.
    let limit = scenario().spec.rig.pose_age;
    let stop = stop_in_time(&twin, hidden_at, limit, |c| {
        c.packet.id == 3 && wheel_speeds(&c.packet.command) == Some((0.0, 0.0))
    });
    assert!(
        rig.report.stops.contains(&"pose_stale".to_string()),
        "{:?}",
        rig.report
    );
    assert!(
        !rig.report.stops.iter().any(|s| s != "pose_stale"),
        "{:?}",
        rig.report
    );
    let moving_after = |id: u8| {
        motion(twin.received())
            .any(|(c, _)| c.at > stop.at && rig.bridge_stopped_at > c.at && c.packet.id == id)
    };
    assert!(!moving_after(3), "the lost robot was driven again");
    assert!(
        [1, 2, 4, 5].iter().all(|&id| moving_after(id)),
        "the others stopped too"
    );
}

/// Checks that the run reported `robot` (radio address) alone as silent, with an event that says
/// `what`.
fn assert_reported_silent(rig: Rig, robot: u8, what: &str) {
    let _twin = rig.twin.join();
    assert_eq!(rig.report.silent_robots, vec![robot], "{:?}", rig.report);
    let events: Vec<String> = rig
        .log
        .iter()
        .filter(|m| m.topic == Topic::Events)
        .map(|m| String::from_utf8_lossy(&m.data).to_string())
        .collect();
    assert!(events.iter().any(|e| e.contains(what)), "{events:?}");
}

/// A robot whose radio goes quiet (it neither obeys nor answers): the bridge notices within about a
/// second of unanswered data requests, says so, and sends it nothing but stops from then on.
#[test]
fn a_robot_that_stops_answering_is_reported() {
    let _alone = one_rig_at_a_time();
    let (channel, url) = udp_channel();
    let rig = run_rig(scenario(), channel, url, 3.0, |_, robots| {
        std::thread::sleep(Duration::from_millis(1000));
        robots.lock().unwrap().deaf = vec![4];
    });
    assert_reported_silent(rig, 4, "robot_silent");
}

/// A robot that never answers at all (switched off, wrong radio address) is reported as silent too,
/// about a second after it was first asked.
#[test]
fn a_robot_that_never_answers_is_reported() {
    let _alone = one_rig_at_a_time();
    let (channel, url) = udp_channel();
    // The last robot is asked last: deaf before the loop's first request reaches it.
    let rig = run_rig(scenario(), channel, url, 2.5, |_, robots| {
        robots.lock().unwrap().deaf = vec![5];
    });
    assert_reported_silent(rig, 5, "never answered");
}
