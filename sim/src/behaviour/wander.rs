//! Random walk.
//!
//! A correlated random walk: the robot drives at `speed` with a turn that is itself a random walk, an
//! Ornstein-Uhlenbeck process sampled exactly at the observation times, so the path bends smoothly
//! and its statistics do not depend on the control rate.
use super::{Behaviour, Observation, WheelCommand};
use crate::rng::SimRng;

pub struct Wander {
    /// Mean wheel speed, m/s.
    pub speed: f32,
    /// Current turn as a fraction of the speed: wheels at `speed * (1 -+ turn)` (positive turns left).
    pub turn: f32,
    /// Stationary standard deviation of `turn`.
    pub turn_std: f32,
    /// Correlation time of `turn`, s.
    pub turn_time: f32,
    /// Time of the previous observation, s.
    pub last_time: Option<f32>,
}

impl Wander {
    /// Default turn std 0.1 (with the Colias 26 mm wheel base a turn radius of about 13 cm at one
    /// std), correlation time 1 s.
    pub fn new(speed: f32) -> Self {
        Wander {
            speed,
            turn: 0.0,
            turn_std: 0.1,
            turn_time: 1.0,
            last_time: None,
        }
    }
}

impl Behaviour for Wander {
    fn name(&self) -> &str {
        "wander"
    }
    fn act(&mut self, obs: &Observation, rng: &mut SimRng) -> WheelCommand {
        let z = crate::rng::normal(rng);
        let std = self.turn_std.max(0.0);
        match self.last_time {
            // First step: start from the stationary distribution.
            None => self.turn = std * z,
            Some(t0) => {
                let dt = (obs.time - t0).max(0.0);
                let a = if self.turn_time > 0.0 {
                    (-dt / self.turn_time).exp()
                } else {
                    0.0
                };
                self.turn = a * self.turn + std * (1.0 - a * a).max(0.0).sqrt() * z;
            }
        }
        if !self.turn.is_finite() {
            self.turn = 0.0;
        }
        self.turn = self.turn.clamp(-1.0, 1.0);
        self.last_time = Some(obs.time);
        WheelCommand::new(
            self.speed * (1.0 - self.turn),
            self.speed * (1.0 + self.turn),
        )
    }
    fn reads_colour(&self) -> bool {
        false
    }
}
