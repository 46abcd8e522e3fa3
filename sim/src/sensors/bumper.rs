//! Three IR bumpers (front-left, front, front-right) and a spatial index of robots for them.
use crate::robot::Pose;
use glam::Vec2;
use serde::{Deserialize, Serialize};

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct BumperParams {
    /// Range of the IR sensors from the robot's rim, m.
    pub range: f32,
    /// Directions of the three sensors relative to the heading, rad (front-left, front, front-right).
    pub angles: [f32; 3],
}

impl Default for BumperParams {
    fn default() -> Self {
        BumperParams { range: 0.02, angles: [std::f32::consts::FRAC_PI_4, 0.0, -std::f32::consts::FRAC_PI_4] }
    }
}

/// Uniform-grid hash of robot positions, rebuilt each step, so bumpers need no ray casts.
#[derive(Default)]
pub struct NeighbourIndex {}

impl NeighbourIndex {
    pub fn rebuild(&mut self, _arena: Vec2, _cell: f32, _positions: &[Vec2]) {
        todo!()
    }
    /// Readings in [0, 1] of robot `index`'s bumpers against walls of an arena of `arena` size and the
    /// other robots (all of radius `radius`).
    pub fn bumpers(&self, _index: usize, _poses: &[Pose], _radius: f32, _arena: Vec2, _params: &BumperParams) -> [f32; 3] {
        todo!()
    }
}
