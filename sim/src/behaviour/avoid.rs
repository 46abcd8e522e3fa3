//! Sharp turn away from a bumper hit, then carry on with an inner behaviour.
use super::{BUMPER_FRONT_LEFT, BUMPER_FRONT_RIGHT, Behaviour, Observation, WheelCommand};
use crate::rng::SimRng;

pub struct Avoid<B> {
    pub inner: B,
    /// A bumper reading above this starts a turn.
    pub threshold: f32,
    /// How long a turn lasts, s.
    pub turn_duration: f32,
    /// Wheel speed of the pivot, m/s (one wheel forward, the other back).
    pub turn_speed: f32,
    /// End time of the turn in progress, s.
    pub turn_until: Option<f32>,
    /// +1 turns left (counter-clockwise), -1 right.
    pub turn_sign: f32,
}

impl<B> Avoid<B> {
    /// Threshold 0.1, a 0.4 s pivot at 0.06 m/s per wheel: about 4.6 rad/s with the Colias wheel
    /// base, so roughly a quarter turn once the motor lag is through.
    pub fn new(inner: B) -> Self {
        Avoid {
            inner,
            threshold: 0.1,
            turn_duration: 0.4,
            turn_speed: 0.06,
            turn_until: None,
            turn_sign: 1.0,
        }
    }

    /// True while a turn is in progress at `time`.
    pub fn turning(&self, time: f32) -> bool {
        self.turn_until.is_some_and(|end| time < end)
    }
}

impl<B: Behaviour> Behaviour for Avoid<B> {
    fn name(&self) -> &str {
        "avoid"
    }
    fn act(&mut self, obs: &Observation, rng: &mut SimRng) -> WheelCommand {
        if !self.turning(obs.time) {
            self.turn_until = None;
            if obs.max_bumper() > self.threshold {
                // More on the left: turn right (clockwise); otherwise turn left.
                let left = obs.bumpers[BUMPER_FRONT_LEFT];
                let right = obs.bumpers[BUMPER_FRONT_RIGHT];
                self.turn_sign = if left > right { -1.0 } else { 1.0 };
                self.turn_until = Some(obs.time + self.turn_duration);
            }
        }
        if self.turn_until.is_some() {
            let s = self.turn_speed * self.turn_sign;
            return WheelCommand::new(-s, s);
        }
        self.inner.act(obs, rng)
    }
    fn reads_colour(&self) -> bool {
        self.inner.reads_colour()
    }
}
