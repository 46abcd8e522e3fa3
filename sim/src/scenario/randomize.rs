//! The `[randomize]` section: domain randomisation. Each key is a range `[low, high]` that a world draws
//! its value from, uniformly, once when it is built (every episode of a batched environment draws
//! anew), so that a policy trained on the simulator meets rigs whose numbers differ from the defaults:
//! latency, pose noise, sensor gain and crosstalk, motor lag, wheel-speed limit. Centre the ranges on
//! the rig's calibrated values.
use super::individual::{Individual, MAX_COMMAND_LATENCY};
use crate::error::{Result, SimError};
use crate::rng::SimRng;
use crate::robot::ColiasParams;
use crate::sensors::ColourSensorParams;
use crate::tracker::TrackerParams;
use rand::RngExt;
use serde::{Deserialize, Serialize};

/// The parts of a scenario that `[randomize]` draws anew.
pub struct Randomized<'a> {
    pub tracker: &'a mut TrackerParams,
    pub sensor: &'a mut ColourSensorParams,
    pub robot: &'a mut ColiasParams,
}

#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RandomizeSpec {
    /// `[tracker] latency`, s.
    pub tracker_latency: Option<[f32; 2]>,
    /// `[tracker] position_noise`, m.
    pub position_noise: Option<[f32; 2]>,
    /// `[tracker] heading_noise`, rad.
    pub heading_noise: Option<[f32; 2]>,
    /// A factor on `[sensor] gain`.
    pub sensor_gain: Option<[f32; 2]>,
    /// Added to each off-diagonal entry of `[sensor] crosstalk` (each drawn on its own).
    pub crosstalk: Option<[f32; 2]>,
    /// `[robot] motor_lag`, s.
    pub motor_lag: Option<[f32; 2]>,
    /// `[robot] max_wheel_speed`, m/s.
    pub max_wheel_speed: Option<[f32; 2]>,
    /// A factor on each wheel's speed scale of each robot (its `[individual]` value, or 1), drawn
    /// per wheel: asymmetric robots around each robot's own values.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub wheel_scale: Option<[f32; 2]>,
    /// A factor on each robot's motor lag (its `[individual]` value, or `[robot] motor_lag`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub motor_lag_factor: Option<[f32; 2]>,
    /// Seconds added to each robot's command latency (its `[individual]` value, or 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub command_latency: Option<[f32; 2]>,
    /// A factor on each robot's own sensor gain (its `[individual]` value, or 1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub robot_sensor_gain: Option<[f32; 2]>,
}

impl RandomizeSpec {
    pub fn is_default(&self) -> bool {
        *self == RandomizeSpec::default()
    }

    /// Each range finite, `low <= high`, and inside what its key allows.
    pub fn validate(&self) -> Result<()> {
        let ranges = [
            ("tracker_latency", self.tracker_latency, 0.0, 1.0),
            ("position_noise", self.position_noise, 0.0, 0.1),
            ("heading_noise", self.heading_noise, 0.0, 1.0),
            ("sensor_gain", self.sensor_gain, 1e-3, 100.0),
            ("crosstalk", self.crosstalk, -0.5, 0.5),
            ("motor_lag", self.motor_lag, 0.0, 1.0),
            ("max_wheel_speed", self.max_wheel_speed, 1e-3, 2.0),
            ("wheel_scale", self.wheel_scale, 0.1, 10.0),
            ("motor_lag_factor", self.motor_lag_factor, 0.0, 10.0),
            ("command_latency", self.command_latency, -1.0, 1.0),
            ("robot_sensor_gain", self.robot_sensor_gain, 0.01, 100.0),
        ];
        for (key, range, lo, hi) in ranges {
            let Some([a, b]) = range else { continue };
            let key = format!("randomize.{key}");
            let show = format!("[{a}, {b}]");
            if !(a.is_finite() && b.is_finite()) || a > b {
                return Err(SimError::invalid(
                    key,
                    show,
                    "must be [low, high] with finite low <= high",
                ));
            }
            if a < lo || b > hi {
                return Err(SimError::invalid(
                    key,
                    show,
                    format!("must lie within [{lo}, {hi}]"),
                ));
            }
        }
        Ok(())
    }

    /// Draws every randomised value into a scenario's tracker, sensor and robot parameters from
    /// `rng`, in a fixed order.
    pub fn apply(&self, spec: Randomized, rng: &mut SimRng) {
        let mut draw =
            |r: Option<[f32; 2]>| r.map(|[a, b]| if a < b { rng.random_range(a..=b) } else { a });
        if let Some(v) = draw(self.tracker_latency) {
            spec.tracker.latency = v;
        }
        if let Some(v) = draw(self.position_noise) {
            spec.tracker.position_noise = v;
        }
        if let Some(v) = draw(self.heading_noise) {
            spec.tracker.heading_noise = v;
        }
        if let Some(v) = draw(self.sensor_gain) {
            spec.sensor.gain *= v;
        }
        if self.crosstalk.is_some() {
            for c in 0..3 {
                for k in 0..3 {
                    if c != k
                        && let Some(v) = draw(self.crosstalk)
                    {
                        spec.sensor.crosstalk[c][k] = (spec.sensor.crosstalk[c][k] + v).max(0.0);
                    }
                }
            }
        }
        if let Some(v) = draw(self.motor_lag) {
            spec.robot.motor_lag = v;
        }
        if let Some(v) = draw(self.max_wheel_speed) {
            spec.robot.max_wheel_speed = v;
        }
    }

    /// Whether any key draws per robot (every robot then gets values of its own).
    pub fn draws_per_robot(&self) -> bool {
        self.wheel_scale.is_some()
            || self.motor_lag_factor.is_some()
            || self.command_latency.is_some()
            || self.robot_sensor_gain.is_some()
    }

    /// Draws each robot's values around its own (`each`, one per robot, `nominal_lag` for those
    /// without a lag of their own) from `rng`, after [`Self::apply`]'s draws: robot by robot, left
    /// and right wheel, lag, latency, gain. Keys left out draw nothing, so adding one never changes
    /// the others' draws.
    pub fn apply_each(&self, each: &mut [Individual], nominal_lag: f32, rng: &mut SimRng) {
        let mut draw =
            |r: Option<[f32; 2]>| r.map(|[a, b]| if a < b { rng.random_range(a..=b) } else { a });
        for robot in each {
            for w in 0..2 {
                if let Some(f) = draw(self.wheel_scale) {
                    robot.wheel_scale[w] *= f;
                }
            }
            if let Some(f) = draw(self.motor_lag_factor) {
                robot.motor_lag = Some(robot.motor_lag.unwrap_or(nominal_lag) * f);
            }
            if let Some(v) = draw(self.command_latency) {
                robot.latency = (robot.latency + v).clamp(0.0, MAX_COMMAND_LATENCY);
            }
            if let Some(f) = draw(self.robot_sensor_gain) {
                robot.sensor_gain *= f;
            }
        }
    }
}
