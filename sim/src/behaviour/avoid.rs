//! Sharp turn away from a bumper hit, then carry on with an inner behaviour.
use super::{Behaviour, Observation, WheelCommand};
use crate::rng::SimRng;

pub struct Avoid<B> {
    pub inner: B,
}

impl<B: Behaviour> Behaviour for Avoid<B> {
    fn name(&self) -> &str {
        "avoid"
    }
    fn act(&mut self, _obs: &Observation, _rng: &mut SimRng) -> WheelCommand {
        todo!()
    }
}
