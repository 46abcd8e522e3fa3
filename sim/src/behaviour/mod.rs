//! Behaviours: a robot's controller. It sees only its own [`Observation`] and returns a
//! [`WheelCommand`]; it never sees the world. The same behaviour runs in the simulator, in the
//! batched environments and on the real robot through the bridge.

mod avoid;
mod follow;
mod observation;
pub mod paper;
pub mod param_doc;
pub mod registry;
mod wander;

pub use avoid::Avoid;
pub use follow::{Follow, FollowParams};
pub use observation::{
    BUMPER_FRONT, BUMPER_FRONT_LEFT, BUMPER_FRONT_RIGHT, Observation, WheelCommand,
};
pub use wander::Wander;

use crate::rng::SimRng;

/// A robot controller: `Observation -> WheelCommand`, called once per control step.
pub trait Behaviour: Send {
    /// Short name used in logs and scenario files (`"wander"`).
    fn name(&self) -> &str;
    /// Decide the wheel command. `rng` is this robot's own random stream.
    fn act(&mut self, obs: &Observation, rng: &mut SimRng) -> WheelCommand;
    /// Whether `act` reads the colour sensors (counts or intensities). A behaviour that does not
    /// lets a batched environment skip evaluating them ([`crate::world::World::skip_unread_colour`]).
    fn reads_colour(&self) -> bool {
        true
    }
}
