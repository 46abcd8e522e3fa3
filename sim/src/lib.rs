//! colcos-sim: the physical world of a ColCOSPhi arena.
//!
//! Pheromone fields ([`field`]), the screen image of eq. (1) ([`screen`]), Colias robots on rapier2d
//! ([`robot`]), their colour sensors and bumpers ([`sensors`]), the overhead tracker ([`tracker`]),
//! behaviours that see only their own robot ([`behaviour`]), scenario files ([`scenario`]) and the
//! [`world`] that steps them together. SI units inside: metres, seconds, radians.
//!
//! Coordinates: the arena spans `x in [0, width]`, `y in [0, height]` with `y` up. A robot's heading is
//! measured counter-clockwise from `+x`; in the robot frame `X+` is forward and `Y+` is left.

pub mod angle;
pub mod arena;
pub mod behaviour;
pub mod channel;
pub mod error;
pub mod field;
pub mod metrics;
pub mod output;
mod prefetch;
pub mod rng;
pub mod robot;
pub mod run;
pub mod scenario;
pub mod screen;
pub mod sensors;
pub mod shield;
pub mod spatial;
pub mod tracker;
pub mod world;

pub use glam::Vec2;

/// The types most users need, in one import.
pub mod prelude {
    pub use crate::behaviour::{Behaviour, Observation, WheelCommand};
    pub use crate::error::SimError;
    pub use crate::robot::Pose;
    pub use crate::scenario::Scenario;
    pub use crate::world::World;
    pub use glam::Vec2;
}
