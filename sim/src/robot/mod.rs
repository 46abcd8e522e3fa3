//! The Colias robot: body, differential drive with motor lag, and the rapier2d physics of a whole arena.

mod actuation;
mod colias;
mod drive;
mod obstacle_contacts;
mod physics;

pub use actuation::Actuation;
pub use colias::ColiasParams;
pub use drive::{DriveState, lag_fraction};
pub use physics::{ArenaPhysics, MAX_HOSTED_ARENAS, PhysicsBackend, RapierHost};

use glam::Vec2;

/// A robot's position (m) and heading (rad, counter-clockwise from +x).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Pose {
    pub pos: Vec2,
    pub heading: f32,
}

impl Pose {
    pub fn new(x: f32, y: f32, heading: f32) -> Self {
        Pose {
            pos: Vec2::new(x, y),
            heading,
        }
    }
    /// Unit vector along the heading.
    pub fn forward(&self) -> Vec2 {
        Vec2::from_angle(self.heading)
    }
    /// A point given in the robot frame (X+ forward, Y+ left), in arena coordinates.
    pub fn to_world(&self, local: Vec2) -> Vec2 {
        self.pos + self.forward().rotate(local)
    }
}
