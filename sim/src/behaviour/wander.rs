//! Random walk.
use super::{Behaviour, Observation, WheelCommand};
use crate::rng::SimRng;

pub struct Wander {
    pub speed: f32,
}

impl Behaviour for Wander {
    fn name(&self) -> &str {
        "wander"
    }
    fn act(&mut self, _obs: &Observation, _rng: &mut SimRng) -> WheelCommand {
        todo!()
    }
}
