//! What each robot's colour sensors should have read: the log's ticks put through the bridge's loop
//! again (its fields, injection and screen: the field it displayed), and at every telemetry's time
//! the scenario's sensor model, without noise, read at the robot's tracked pose there. Beside each
//! prediction, how much it changes when the pose is off by the tracker's error: near an edge of the
//! pattern a millimetre decides what the sensor saw, so such readings say little about the sensor.
use super::series::RobotSeries;
use crate::protocol::colias::LegacyDrive;
use crate::rig::LoopCore;
use crate::rig::replay::{RecordedTick, feed};
use colcos_sim::error::Result;
use colcos_sim::field::FrozenSources;
use colcos_sim::rng::{self, Stream};
use colcos_sim::robot::Pose;
use colcos_sim::scenario::Scenario;
use colcos_sim::sensors::{
    ColourSensor, ColourSensorParams, SENSOR_RADIUS, ScreenView, sensor_positions,
};
use colcos_sim::world::World;
use glam::Vec2;

/// How far off the tracked pose may be, for the steadiness of a prediction: position (m) and
/// heading (rad), a few times the tracker's noise plus what a robot moves in a tick.
pub const POSE_DOUBT: (f32, f32) = (0.002, 0.04);

/// One telemetry reading beside its prediction.
#[derive(Clone, Copy, Debug)]
pub struct Reading {
    /// When the robot read, s since the run's start.
    pub t: f64,
    /// Counts the robot reported, simulator sensor order, (r, g, b) each.
    pub observed: [[u16; 3]; 4],
    /// Counts the nominal sensor model gives at the tracked pose.
    pub predicted: [[f64; 3]; 4],
    /// Per sensor, the largest change of any channel's prediction over poses within
    /// [`POSE_DOUBT`]: counts.
    pub unsteady: [f64; 4],
}

/// Every robot's readings of the log `ticks` (with `series` from them) against `scenario`'s
/// sensor model over the field the bridge displayed, and the model's counts on a white screen
/// (its largest channel: the scale the steadiness is judged on).
pub fn predict_readings(
    ticks: &[RecordedTick],
    scenario: &Scenario,
    series: &[RobotSeries],
) -> Result<(Vec<Vec<Reading>>, f64)> {
    // The robots' nominal sensors and the printed obstacles, from a world of the scenario: the
    // `[individual]` gains are not applied (identification fits them afresh).
    let world = World::new(scenario)?;
    let quiet = ColourSensor::new(ColourSensorParams {
        noise: 0.0,
        ..*world.sensor().params()
    });
    let printed = world.obstacles().printed();
    let screen = *world.screen();
    let mut core = LoopCore::new(scenario, LegacyDrive::default())?;
    let mut rng = rng::stream_of(scenario.spec.seed, 0, Stream::Telemetry(0));
    let white = quiet
        .counts([255.0; 3], &mut rng)
        .into_iter()
        .max()
        .unwrap_or(0) as f64;
    // Every robot's readings in the order of their times, each predicted once the replay has
    // reached that time.
    let mut pending: Vec<(f64, usize, [[u16; 3]; 4])> = (series.iter().enumerate())
        .flat_map(|(i, s)| s.telemetry.iter().map(move |(t, c)| (*t, i, *c)))
        .collect();
    pending.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut out = vec![Vec::new(); series.len()];
    let mut next = 0;
    for tick in ticks {
        feed(&mut core, tick, &[]);
        if next >= pending.len() || pending[next].0 > tick.t {
            continue;
        }
        let pheromones = core.host().pheromones();
        let frozen = FrozenSources::new(pheromones);
        let view = ScreenView {
            pheromones,
            frozen: &frozen,
            screen: &screen,
            printed,
        };
        let read = |pose: &Pose, i: usize, rng: &mut colcos_sim::rng::SimRng| -> [[u16; 3]; 4] {
            let points = sensor_positions(pose, SENSOR_RADIUS);
            match world.robot_sensors(i) {
                // Robots with sensors of their own (`[sensor] per_robot`): each its own model.
                Some(own) => std::array::from_fn(|k| {
                    let sum = own.truth[k].footprint_sums_in(&view, &[points[k]])[0];
                    own.truth[k].counts_of_sum(sum, rng)
                }),
                None => quiet.read_all_in(&view, &points, rng),
            }
        };
        while next < pending.len() && pending[next].0 <= tick.t {
            let (t, i, observed) = pending[next];
            next += 1;
            let Some(pose) = pose_at(&series[i].poses, t) else {
                continue;
            };
            let at = read(&pose, i, &mut rng);
            let mut unsteady = [0.0f64; 4];
            let (d, h) = POSE_DOUBT;
            let nearby = [
                (Vec2::new(d, 0.0), 0.0),
                (Vec2::new(-d, 0.0), 0.0),
                (Vec2::new(0.0, d), 0.0),
                (Vec2::new(0.0, -d), 0.0),
                (Vec2::ZERO, h),
                (Vec2::ZERO, -h),
            ];
            for (dp, dh) in nearby {
                let moved = Pose::new(pose.pos.x + dp.x, pose.pos.y + dp.y, pose.heading + dh);
                let there = read(&moved, i, &mut rng);
                for k in 0..4 {
                    for c in 0..3 {
                        let change = (there[k][c] as f64 - at[k][c] as f64).abs();
                        unsteady[k] = unsteady[k].max(change);
                    }
                }
            }
            out[i].push(Reading {
                t,
                observed,
                predicted: at.map(|s| s.map(|c| c as f64)),
                unsteady,
            });
        }
    }
    Ok((out, white))
}

/// The robot's pose at `t` from its captures (linear between the two around it); `None` outside
/// them or across a gap of more than 0.15 s (a lost robot).
fn pose_at(poses: &[(f64, [f64; 3])], t: f64) -> Option<Pose> {
    let k = poses.partition_point(|(at, _)| *at <= t);
    if k == 0 || k >= poses.len() {
        return None;
    }
    let ((a, p), (b, q)) = (poses[k - 1], poses[k]);
    if b - a > 0.15 {
        return None;
    }
    let f = if b > a { (t - a) / (b - a) } else { 0.0 };
    let turn = super::windows::wrap(q[2] - p[2]);
    Some(Pose::new(
        (p[0] + (q[0] - p[0]) * f) as f32,
        (p[1] + (q[1] - p[1]) * f) as f32,
        (p[2] + turn * f) as f32,
    ))
}
