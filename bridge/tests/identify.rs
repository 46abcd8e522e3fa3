//! `colcos rig identify`'s fit against known truths: robots with their own wheel scales, motor lag
//! and command latency (`[individual]`) driven by the excitation in the simulator, their poses
//! delivered as a tracker would (1 mm and 0.02 rad of noise, 40 ms old), recorded as the bridge's
//! ticks; the fit must find every wheel scale within 5 %, every latency within 5 ms and every motor
//! lag within 20 %. The arena is large (4 m) so that the robots, which no shield guards here, rarely
//! touch a wall: on the rig the shield keeps them off. Bad input is refused with the reason.
use colcos_bridge::identify::{Excitation, FitOptions, fit_robot, robot_series};
use colcos_bridge::protocol::colias::{CommandPacket, HostCommand};
use colcos_bridge::rig::PoseIn;
use colcos_bridge::rig::replay::RecordedTick;
use colcos_sim::behaviour::WheelCommand;
use colcos_sim::robot::Pose;
use colcos_sim::scenario::Scenario;
use colcos_sim::world::World;

const SCENARIO: &str = r#"
name = "identify"
duration = 120.0
[screen]
resolution = [200, 200]
size = [4.0, 4.0]
[sensor]
noise = 0.0
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
/// ticks: each tick the poses captured two ticks earlier, then the commands sent.
fn record(truth: &str, seconds: f64, seed: u64) -> (Scenario, Vec<RecordedTick>) {
    let host = Scenario::from_toml_str(SCENARIO, ".").unwrap();
    let sc = Scenario::from_toml_str(&format!("{SCENARIO}\n{truth}"), ".").unwrap();
    let mut world = World::new(&sc).unwrap();
    let n = sc.robot_count();
    let radio = sc.spec.rig.radio_addresses(n).unwrap();
    let dt = sc.spec.dt as f64;
    let excite = Excitation::new(seed, 0.12);
    let mut noise = Noise(seed);
    let mut history: Vec<Vec<Pose>> = Vec::new();
    let mut ticks = Vec::new();
    for k in 0..(seconds / dt).round() as u64 {
        let t = k as f64 * dt;
        history.push(world.poses().to_vec());
        let mut tick = RecordedTick {
            tick: k + 1,
            t,
            step: dt,
            stopped: vec![false; n],
            ..Default::default()
        };
        if k >= 2 {
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
            let cmd = HostCommand::WheelSpeeds {
                left: c.left,
                right: c.right,
            };
            let packet = CommandPacket::new(radio[i], (t * 1000.0) as u32, cmd);
            tick.commands.push(packet.to_frame());
        }
        world.step_with_commands(&cmds);
        ticks.push(tick);
    }
    (host, ticks)
}

/// (wheel scales, motor lag, latency) of each robot of a truth.
type Truth = [([f64; 2], f64, f64); 3];

fn truth_toml(truth: &Truth) -> String {
    truth
        .iter()
        .enumerate()
        .map(|(i, (s, lag, lat))| {
            format!(
                "[[individual.robot]]\nindex = {i}\nwheel_scale = [{}, {}]\nmotor_lag = {lag}\nlatency = {lat}\n",
                s[0], s[1]
            )
        })
        .collect()
}

fn check(truth: &Truth, seed: u64) {
    let (sc, ticks) = record(&truth_toml(truth), 60.0, seed);
    let series = robot_series(&ticks, &sc).unwrap();
    let opts = FitOptions {
        wheel_base: sc.spec.robot.wheel_base as f64,
        ..FitOptions::default()
    };
    for (i, (s, lag, lat)) in truth.iter().enumerate() {
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
            assert!(
                (scale[w] - s[w]).abs() / s[w] < 0.05,
                "robot {i} wheel {w}: {scale:?} vs {s:?}"
            );
        }
        assert!(
            (got_lag - lag).abs() / lag < 0.2,
            "robot {i} lag {got_lag} vs {lag}"
        );
        assert!(
            (got_lat - lat).abs() < 0.005,
            "robot {i} latency {got_lat} vs {lat}"
        );
    }
}

#[test]
fn identifies_the_first_truth() {
    check(
        &[
            ([1.0, 0.9], 0.05, 0.04),
            ([0.85, 1.0], 0.08, 0.0),
            ([1.1, 1.05], 0.03, 0.1),
        ],
        1,
    );
}

#[test]
fn identifies_the_second_truth() {
    check(
        &[
            ([0.95, 0.95], 0.12, 0.02),
            ([1.0, 0.8], 0.04, 0.06),
            ([0.9, 1.1], 0.06, 0.08),
        ],
        2,
    );
}

#[test]
fn identifies_the_third_truth() {
    check(
        &[
            ([1.2, 1.0], 0.1, 0.12),
            ([0.7, 0.75], 0.02, 0.04),
            ([1.0, 1.0], 0.05, 0.0),
        ],
        3,
    );
}

#[test]
fn too_little_data_names_what_cannot_be_identified() {
    let (sc, ticks) = record("", 0.6, 4);
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
    // Driving straight on: the turning is seen but nothing changes, so the lag and latency cannot be.
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
