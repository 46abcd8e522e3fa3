//! rapier2d world of one arena: walls and robot discs, driven by velocity.
use super::{ColiasParams, Pose};
use glam::Vec2;

pub struct ArenaPhysics {
    // rapier sets, handles ...
}

impl ArenaPhysics {
    /// An arena of `size` (m) with walls, and one robot at each pose.
    pub fn new(_size: Vec2, _params: &ColiasParams, _poses: &[Pose]) -> Self {
        todo!()
    }
    /// Drives every robot with its body velocity (forward m/s, yaw rate rad/s) for `dt`, resolving
    /// contacts with walls and each other.
    pub fn step(&mut self, _velocities: &[(f32, f32)], _dt: f32) {
        todo!()
    }
    /// True poses after the last step.
    pub fn poses(&self) -> &[Pose] {
        todo!()
    }
}
