//! `colcos rig identify`'s fit against known truths: robots with their own wheel scales, motor lag,
//! command latency and colour gain and offset (`[individual]`) driven by the excitation in the
//! simulator over a screen of printed stripes, their poses delivered as a tracker would (1 mm and
//! 0.02 rad of noise, 40 ms old) and their colour counts as telemetry answering the loop's requests,
//! recorded as the bridge's ticks; the fit must find every wheel scale within 5 %, every latency
//! within 5 ms, every motor lag within 20 % and every sensor gain within 10 %. The arena is large
//! (4 m) so that the robots, which no shield guards here, rarely touch a wall: on the rig the shield
//! keeps them off. Bad input is refused with the reason.
use colcos_bridge::identify::excite::check_room;
use colcos_bridge::identify::overlay::overlay;
use colcos_bridge::identify::readings::predict_readings;
use colcos_bridge::identify::{
    Excitation, FitOptions, STEADY_FRACTION, fit_robot, fit_sensor, identify, robot_series,
};
use colcos_bridge::protocol::colias::{CommandPacket, HostCommand, Telemetry, colour_from_sim};
use colcos_bridge::rig::PoseIn;
use colcos_bridge::rig::recorder::{Recorder, Topic};
use colcos_bridge::rig::replay::RecordedTick;
use colcos_sim::behaviour::WheelCommand;
use colcos_sim::robot::Pose;
use colcos_sim::scenario::{IndividualFile, Scenario};
use colcos_sim::world::World;

const SCENARIO: &str = r#"
name = "identify"
duration = 120.0
[screen]
resolution = [200, 200]
size = [4.0, 4.0]
[sensor]
noise = 20.0
[tracker]
latency = 0.0
position_noise = 0.0
heading_noise = 0.0
dropout = 0.0
[[robots]]
count = 3
behaviour = "wander"
placement = "explicit"
poses = [[1.5, 1.5, 0.0], [2.5, 1.5, 90.0], [2.0, 2.5, 180.0]]
"#;

/// Printed stripes over the arena: white ones along x, orange ones along y, 25 cm apart, on the
/// black screen: what the sensors see changes every few seconds.
fn stripes(size: f32) -> String {
    let mut out = String::new();
    let mut v = 0.3f32;
    while v < size - 0.2 {
        out += &format!(
            "[[obstacles]]\nshape = \"wall\"\nkind = \"printed\"\ncolour = [255, 255, 255]\n\
             points = [[0.1, {v}], [{e}, {v}]]\nthickness = 0.1\n\
             [[obstacles]]\nshape = \"wall\"\nkind = \"printed\"\ncolour = [255, 90, 0]\n\
             points = [[{v}, 0.1], [{v}, {e}]]\nthickness = 0.06\n",
            e = size - 0.1
        );
        v += 0.25;
    }
    out
}

/// splitmix64-driven standard normal draws (Box-Muller), for the tracker's noise.
struct Noise(u64);
impl Noise {
    fn unit(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
    fn normal(&mut self) -> f64 {
        let (a, b) = (self.unit().max(1e-12), self.unit());
        (-2.0 * a.ln()).sqrt() * (std::f64::consts::TAU * b).cos()
    }
}

/// `seconds` of excitation of a world with `truth` (inline `[individual]` entries) as the bridge's
/// ticks, as the live loop makes them: every `pose_every` ticks the poses captured two ticks
/// earlier; the commands that changed (and every 0.5 s the unchanged ones); every third tick a
/// data request to one robot in turn, which answers in the next tick with the colour counts it read
/// when asked. `screen`: what is printed on the screen (TOML).
fn record(
    truth: &str,
    screen: &str,
    seconds: f64,
    seed: u64,
    pose_every: u64,
) -> (Scenario, Vec<RecordedTick>) {
    let host = Scenario::from_toml_str(&format!("{SCENARIO}\n{screen}"), ".").unwrap();
    let sc = Scenario::from_toml_str(&format!("{SCENARIO}\n{screen}\n{truth}"), ".").unwrap();
    let mut world = World::new(&sc).unwrap();
    let n = sc.robot_count();
    let radio = sc.spec.rig.radio_addresses(n).unwrap();
    let dt = sc.spec.dt as f64;
    let excite = Excitation::new(seed, 0.12);
    let mut noise = Noise(seed);
    let mut history: Vec<Vec<Pose>> = Vec::new();
    let mut ticks = Vec::new();
    let mut answer: Option<Telemetry> = None;
    let mut sent = vec![(WheelCommand::STOP, f64::NEG_INFINITY); n];
    for k in 0..(seconds / dt).round() as u64 {
        let t = k as f64 * dt;
        history.push(world.poses().to_vec());
        let mut tick = RecordedTick {
            tick: k + 1,
            t,
            step: dt,
            stopped: vec![false; n],
            telemetry: answer.take().into_iter().collect(),
            ..Default::default()
        };
        if k >= 2 && k % pose_every == 0 {
            let seen = &history[k as usize - 2];
            tick.poses = (0..n)
                .map(|i| PoseIn {
                    id: sc.spec.rig.tracker_id(i) as u32,
                    pose: Pose::new(
                        seen[i].pos.x + 0.001 * noise.normal() as f32,
                        seen[i].pos.y + 0.001 * noise.normal() as f32,
                        seen[i].heading + 0.02 * noise.normal() as f32,
                    ),
                    age: 2.0 * dt,
                    fresh: true,
                })
                .collect();
        }
        let cmds: Vec<WheelCommand> = (0..n).map(|i| excite.command(i, t)).collect();
        for (i, c) in cmds.iter().enumerate() {
            if *c == sent[i].0 && t - sent[i].1 < 0.5 {
                continue;
            }
            sent[i] = (*c, t);
            let cmd = HostCommand::WheelSpeeds {
                left: c.left,
                right: c.right,
            };
            let packet = CommandPacket::new(radio[i], (t * 1000.0) as u32, cmd);
            tick.commands.push(packet.to_frame());
        }
        // A robot reads as it hears the request (the counts of the poses now).
        let asked = (k / 3) as usize % n;
        if k > 0 && k % 3 == 0 {
            let request = HostCommand::RequestTelemetry(1);
            let packet = CommandPacket::new(radio[asked], (t * 1000.0) as u32, request);
            tick.commands.push(packet.to_frame());
            answer = Some(Telemetry {
                id: radio[asked],
                sys_t_ms: (t * 1000.0) as u32,
                colour: colour_from_sim(world.observations()[asked].counts),
                ..Telemetry::default()
            });
        }
        world.step_with_commands(&cmds);
        ticks.push(tick);
    }
    (host, ticks)
}

/// (wheel scales, motor lag, latency, (sensor gain, offset)) of each robot of a truth.
type Truth = [([f64; 2], f64, f64, (f64, f64)); 3];

fn truth_toml(truth: &Truth) -> String {
    truth
        .iter()
        .enumerate()
        .map(|(i, (s, lag, lat, (g, o)))| {
            format!(
                "[[individual.robot]]\nindex = {i}\nwheel_scale = [{}, {}]\nmotor_lag = {lag}\nlatency = {lat}\n\
                 sensor_gain = {g}\nsensor_offset = {o}\n",
                s[0], s[1]
            )
        })
        .collect()
}

fn check(truth: &Truth, seed: u64) {
    let (sc, ticks) = record(&truth_toml(truth), &stripes(4.0), 60.0, seed, 1);
    let series = robot_series(&ticks, &sc).unwrap();
    let (readings, white) = predict_readings(&ticks, &sc, &series).unwrap();
    let opts = FitOptions {
        wheel_base: sc.spec.robot.wheel_base as f64,
        ..FitOptions::default()
    };
    for (i, (s, lag, lat, (gain, offset))) in truth.iter().enumerate() {
        let sensor = fit_sensor(&readings[i], STEADY_FRACTION * white);
        let (got_gain, gain_sd) = sensor.gain.clone().unwrap();
        let (got_offset, offset_sd) = sensor.offset.clone().unwrap();
        println!(
            "seed {seed} robot {i}: sensor gain {got_gain:.4} +- {gain_sd:.5} (truth {gain}), offset \
             {got_offset:.1} +- {offset_sd:.1} (truth {offset}); {} of {} readings, rms {:.1} counts",
            sensor.used, sensor.readings, sensor.rms
        );
        assert_fraction(&format!("robot {i} sensor gain"), got_gain, *gain, 0.1);
        // The offset's scale is the dark counts' (30) and the screen's black: within 100 counts.
        assert_near(
            &format!("robot {i} sensor offset"),
            got_offset,
            *offset,
            100.0,
        );
        let fit = fit_robot(i, &series[i].commands, &series[i].poses, &opts);
        let (scale, scale_sd) = fit.wheel_scale.clone().unwrap();
        let (got_lag, lag_sd) = fit.motor_lag.clone().unwrap();
        let (got_lat, lat_sd) = fit.latency.clone().unwrap();
        println!(
            "seed {seed} robot {i}: scales {scale:.4?} +- {scale_sd:.4?} (truth {s:?}), lag {got_lag:.4} +- {lag_sd:.4} \
             (truth {lag}), latency {got_lat:.4} +- {lat_sd:.4} (truth {lat}); {} windows, {} outliers",
            fit.windows, fit.outliers
        );
        // The tracker's noise (1 mm, 0.02 rad) seen in the residuals, a little above it.
        let (p, h) = (fit.rms[1] / 2f64.sqrt(), fit.rms[0] / 2f64.sqrt());
        println!("  noise at most {:.2} mm, {h:.4} rad", 1e3 * p);
        assert!(
            (0.0008..0.002).contains(&p) && (0.015..0.03).contains(&h),
            "{p} {h}"
        );
        for w in 0..2 {
            assert_fraction(&format!("robot {i} wheel {w}"), scale[w], s[w], 0.05);
        }
        assert_fraction(&format!("robot {i} lag"), got_lag, *lag, 0.2);
        assert_near(&format!("robot {i} latency"), got_lat, *lat, 0.005);
    }
}

/// Asserts that `got` is within `tol` of the `truth` of `what`.
fn assert_near(what: &str, got: f64, truth: f64, tol: f64) {
    assert!((got - truth).abs() < tol, "{what} {got} vs {truth}");
}

/// Asserts that `got` is within the fraction `tol` of the `truth` of `what`.
fn assert_fraction(what: &str, got: f64, truth: f64, tol: f64) {
    assert!((got - truth).abs() / truth < tol, "{what} {got} vs {truth}");
}

/// Three truths, each with the seed of its excitation and tracker noise.
const TRUTHS: [(Truth, u64); 3] = [
    (
        [
            ([1.0, 0.9], 0.05, 0.04, (0.8, 120.0)),
            ([0.85, 1.0], 0.08, 0.0, (1.0, 0.0)),
            ([1.1, 1.05], 0.03, 0.1, (1.25, -300.0)),
        ],
        1,
    ),
    (
        [
            ([0.95, 0.95], 0.12, 0.02, (1.1, 50.0)),
            ([1.0, 0.8], 0.04, 0.06, (0.7, 400.0)),
            ([0.9, 1.1], 0.06, 0.08, (0.95, -100.0)),
        ],
        2,
    ),
    (
        [
            ([1.2, 1.0], 0.1, 0.12, (1.4, 0.0)),
            ([0.7, 0.75], 0.02, 0.04, (0.6, 200.0)),
            ([1.0, 1.0], 0.05, 0.0, (0.9, 30.0)),
        ],
        3,
    ),
];

#[test]
fn identifies_every_truth() {
    for (truth, seed) in &TRUTHS {
        check(truth, *seed);
    }
}

#[test]
fn too_little_data_names_what_cannot_be_identified() {
    let (sc, ticks) = record("", &stripes(4.0), 0.6, 4, 1);
    let series = robot_series(&ticks, &sc).unwrap();
    let fit = fit_robot(
        0,
        &series[0].commands,
        &series[0].poses,
        &FitOptions::default(),
    );
    for p in [
        fit.wheel_scale.clone().err(),
        fit.latency.clone().err(),
        fit.motor_lag.clone().err(),
    ] {
        let why = p.expect("no number from too little data");
        assert!(why.contains("too little data"), "{why}");
    }
    let mut still = ticks.clone();
    for t in &mut still {
        t.commands.clear();
    }
    let err = robot_series(&still, &sc).unwrap_err().to_string();
    assert!(err.contains("no wheel commands"), "{err}");
    let mut blind = ticks.clone();
    for t in &mut blind {
        t.poses.clear();
    }
    let err = robot_series(&blind, &sc).unwrap_err().to_string();
    assert!(err.contains("no poses"), "{err}");
    assert!(
        robot_series(&[], &sc)
            .unwrap_err()
            .to_string()
            .contains("no ticks")
    );
}

#[test]
fn a_robot_that_saw_one_colour_has_no_sensor_gain() {
    // A black screen: every count is the dark counts, which a gain and an offset explain alike.
    let (sc, ticks) = record("", "", 20.0, 5, 1);
    let series = robot_series(&ticks, &sc).unwrap();
    let (readings, white) = predict_readings(&ticks, &sc, &series).unwrap();
    for r in &readings {
        assert!(r.len() > 100, "{} readings", r.len());
        let why = fit_sensor(r, STEADY_FRACTION * white).gain.unwrap_err();
        assert!(why.contains("too little contrast"), "{why}");
    }
    // Without telemetry, the sensor says so.
    let why = fit_sensor(&[], 400.0).gain.unwrap_err();
    assert!(why.contains("no telemetry"), "{why}");
}

/// `ticks` as the rig log `colcos bridge` writes (the topics `colcos rig identify` reads), for a
/// run of `sc` whose pose ages are exact (no tracker delivery left out).
fn write_log(path: &std::path::Path, sc: &Scenario, ticks: &[RecordedTick]) {
    let mut rec = Recorder::create(path).unwrap();
    let meta = [
        ("scenario", sc.spec.name.clone()),
        ("robots", sc.robot_count().to_string()),
        ("tracker_latency", "0".to_string()),
    ];
    rec.write_metadata("rig", meta.map(|(k, v)| (k.to_string(), v)).into())
        .unwrap();
    for tick in ticks {
        let t_ns = (tick.t * 1e9) as u64;
        if !tick.poses.is_empty() {
            let poses: Vec<_> = (tick.poses.iter())
                .map(|p| {
                    serde_json::json!({"id": p.id, "x": p.pose.pos.x, "y": p.pose.pos.y,
                        "heading": p.pose.heading, "age": p.age, "fresh": p.fresh})
                })
                .collect();
            let json = serde_json::to_vec(&poses).unwrap();
            rec.record(Topic::Poses, t_ns, &json).unwrap();
        }
        for tm in &tick.telemetry {
            rec.record(Topic::Telemetry, t_ns, &tm.to_frame()).unwrap();
        }
        for c in &tick.commands {
            rec.record(Topic::Commands, t_ns, c).unwrap();
        }
        let marker = serde_json::json!({"tick": tick.tick, "t": tick.t, "step": tick.step,
            "stopped": [], "commands": tick.commands.len()});
        rec.record(Topic::Ticks, t_ns, marker.to_string().as_bytes())
            .unwrap();
    }
    rec.finish().unwrap();
}

/// The small log the Python tests identify (`bridge/tests/data/identify`): 10 s of three robots
/// with a truth over the stripes. `COLCOS_WRITE_FIXTURES=1` writes it anew; the committed one and
/// this run's must both identify to the truth.
#[test]
fn a_rig_log_identifies_end_to_end_and_bad_logs_are_refused() {
    let truth: Truth = [
        ([1.0, 0.9], 0.05, 0.04, (0.8, 120.0)),
        ([0.85, 1.0], 0.08, 0.0, (1.0, 0.0)),
        ([1.1, 1.05], 0.03, 0.1, (1.25, 60.0)),
    ];
    let screen = stripes(4.0);
    let (sc, ticks) = record(&truth_toml(&truth), &screen, 10.0, 1, 1);
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("rig.mcap");
    write_log(&log, &sc, &ticks);
    let bytes = std::fs::read(&log).unwrap();
    let fixture = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/identify");
    let scenario_text = format!("{SCENARIO}\n{screen}");
    let truth_text = truth_toml(&truth).replace("[[individual.robot]]", "[[robot]]");
    if std::env::var_os("COLCOS_WRITE_FIXTURES").is_some() {
        std::fs::create_dir_all(&fixture).unwrap();
        std::fs::write(fixture.join("rig.mcap"), &bytes).unwrap();
        std::fs::write(fixture.join("scenario.toml"), &scenario_text).unwrap();
        std::fs::write(fixture.join("truth.toml"), &truth_text).unwrap();
    }
    let committed = std::fs::read(fixture.join("rig.mcap")).unwrap();
    let on_file = std::fs::read_to_string(fixture.join("scenario.toml")).unwrap();
    assert_eq!(on_file, scenario_text);
    assert_eq!(
        std::fs::read_to_string(fixture.join("truth.toml")).unwrap(),
        truth_text
    );

    for log in [&committed, &bytes] {
        check_log(log, &sc, &truth);
    }
    let found = identify(&bytes, &sc, &FitOptions::default()).unwrap();
    let file = overlay(&found, "rig.mcap", &sc.spec.name);
    let again = IndividualFile::parse(&file.to_toml()).unwrap();
    assert_eq!(again.robot.len(), 3);
    assert!(again.robot.iter().all(|r| r.sensor_gain.is_some()));

    // Refused, naming why: another scenario, a log without commands, without poses, not a log.
    let other =
        Scenario::from_toml_str(&scenario_text.replace("\"identify\"", "\"other\""), ".").unwrap();
    let err = identify(&bytes, &other, &FitOptions::default()).unwrap_err();
    assert!(err.to_string().contains("not \"other\""), "{err}");
    let strip = |keep: &dyn Fn(&mut RecordedTick)| {
        let mut t = ticks.clone();
        t.iter_mut().for_each(keep);
        let path = dir.path().join("stripped.mcap");
        write_log(&path, &sc, &t);
        let err = identify(&std::fs::read(&path).unwrap(), &sc, &FitOptions::default());
        err.unwrap_err().to_string()
    };
    let err = strip(&|t| t.commands.clear());
    assert!(err.contains("no wheel commands"), "{err}");
    let err = strip(&|t| t.poses.clear());
    assert!(err.contains("no poses"), "{err}");
    let err = identify(b"not a log", &sc, &FitOptions::default()).unwrap_err();
    assert!(err.to_string().contains("no tick records"), "{err}");
}

/// `log` (of `sc`) identifies to `truth`: scales within 5 %, latency within 20 ms (a short log; 60 s
/// give 5 ms), sensor gain within 10 %.
fn check_log(log: &[u8], sc: &Scenario, truth: &Truth) {
    let found = identify(log, sc, &FitOptions::default()).unwrap();
    assert_eq!(found.pose_delay, 0.0);
    for (f, (s, _, lat, (gain, _))) in found.robots.iter().zip(truth) {
        let (scale, _) = f.wheel_scale.clone().unwrap();
        let (got_lat, _) = f.latency.clone().unwrap();
        let (got_gain, _) = f.sensor.gain.clone().unwrap();
        println!(
            "robot {}: scales {scale:.4?}, latency {got_lat:.4}, gain {got_gain:.4}",
            f.index
        );
        assert!((0..2).all(|w| (scale[w] - s[w]).abs() / s[w] < 0.05));
        assert!((got_lat - lat).abs() < 0.02, "{got_lat} vs {lat}");
        assert!((got_gain - gain).abs() / gain < 0.1, "{got_gain} vs {gain}");
    }
}

#[test]
fn an_excitation_that_would_leave_the_arena_is_refused() {
    let room = |extra: &str| {
        let sc = Scenario::from_toml_str(&format!("{SCENARIO}\n{extra}"), ".").unwrap();
        check_room(&sc, 0.14)
    };
    assert_eq!(room(""), Ok(()));
    let why = room("[rig]\nshield = { margin = 0.01 }").unwrap_err();
    assert!(
        why.contains("shield.margin = 0.01") && why.contains("radius"),
        "{why}"
    );
    let why = room("[rig]\nshield = { horizon = 0.0 }\n[robot]\nmotor_lag = 0.3").unwrap_err();
    assert!(
        why.contains("while it stops") && why.contains("--speed"),
        "{why}"
    );
    let small = SCENARIO
        .replace("size = [4.0, 4.0]", "size = [0.15, 0.15]")
        .replace(
            "poses = [[1.5, 1.5, 0.0], [2.5, 1.5, 90.0], [2.0, 2.5, 180.0]]",
            "poses = [[0.05, 0.05, 0.0], [0.1, 0.05, 0.0], [0.05, 0.1, 0.0]]",
        );
    let sc = Scenario::from_toml_str(&small, ".").unwrap();
    let why = check_room(&sc, 0.14).unwrap_err();
    assert!(why.contains("inside the shield's walls"), "{why}");
    assert!(check_room(&Scenario::from_toml_str(SCENARIO, ".").unwrap(), 0.0).is_err());
}
