//! The overhead tracker: poses at its own rate, with latency, noise and dropouts.
use crate::rng::SimRng;
use crate::robot::Pose;
use serde::{Deserialize, Serialize};

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct TrackerParams {
    /// Frames per second.
    pub rate_hz: f32,
    /// Delay from capture to delivery, s.
    pub latency: f32,
    /// Position noise standard deviation, m.
    pub position_noise: f32,
    /// Heading noise standard deviation, rad.
    pub heading_noise: f32,
    /// Probability that a robot is missing from a frame.
    pub dropout: f32,
}

impl Default for TrackerParams {
    fn default() -> Self {
        TrackerParams { rate_hz: 30.0, latency: 0.04, position_noise: 0.001, heading_noise: 0.02, dropout: 0.01 }
    }
}

/// A tracked pose as the host sees it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TrackedPose {
    pub pose: Pose,
    /// Capture time of the frame this pose comes from, s.
    pub stamp: f32,
    /// False until the robot has been seen once.
    pub seen: bool,
}

pub struct Tracker {
    pub params: TrackerParams,
}

impl Tracker {
    pub fn new(_params: TrackerParams, _robots: usize) -> Self {
        todo!()
    }
    /// Records the true poses at time `t` and returns the latest delivered tracked poses (a robot that
    /// dropped out keeps its last tracked pose).
    pub fn update(&mut self, _t: f32, _true_poses: &[Pose], _rng: &mut SimRng) -> &[TrackedPose] {
        todo!()
    }
}
