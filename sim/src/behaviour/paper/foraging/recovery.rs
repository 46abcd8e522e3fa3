//! Recovering a lost trail. A robot that follows a trail into a bend sharper than it can steer (a
//! branch curving away right after its fork, a polyline's corner) runs off its outer edge; wandering
//! from there rarely finds the trail again. So when every sensor has just left the LAP, the robot
//! pivots in place toward the side where its sensors last saw more of it, by up to `recover_turn`
//! degrees at `recover_rate` rad/s; it takes up the trail as soon as any sensor sees the LAP again, and
//! wanders only if the pivot found nothing. All it uses is its own left and right sensors' past
//! readings and the clock.
use super::super::{BLUE, SENSOR_LEFT, SENSOR_RIGHT};
use super::Side;
use crate::behaviour::{Observation, WheelCommand};

/// What the robot remembers of the trail it lost.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Recovery {
    /// The side on which the left and right sensors last saw more LAP.
    last_side: Option<Side>,
    /// When a sensor last saw the LAP, s.
    last_seen: Option<f32>,
    /// Start of the pivot under way, and its side.
    pivot: Option<(f32, Side)>,
}

impl Recovery {
    /// Notes a step with a sensor on the LAP: the trail is not lost, and its side is remembered.
    pub fn on_trail(&mut self, obs: &Observation) {
        let (l, r) = (
            obs.intensity[SENSOR_LEFT][BLUE],
            obs.intensity[SENSOR_RIGHT][BLUE],
        );
        if l > r {
            self.last_side = Some(Side::Left);
        } else if r > l {
            self.last_side = Some(Side::Right);
        }
        self.last_seen = Some(obs.time);
        self.pivot = None;
    }

    /// Forgets the trail (after a bumper hit, or once the pivot has found nothing).
    pub fn forget(&mut self) {
        *self = Recovery::default();
    }

    /// With no sensor on the LAP at `time`: the side to pivot toward, while a pivot of `turn_deg` at
    /// `rate` rad/s that started within `grace` seconds of losing the trail is under way.
    pub fn pivot_side(&mut self, time: f32, turn_deg: f32, rate: f32, grace: f32) -> Option<Side> {
        let duration = turn_deg.to_radians() / rate.max(1e-3);
        if let Some((start, side)) = self.pivot {
            if time - start < duration {
                return Some(side);
            }
            self.forget();
            return None;
        }
        let (side, seen) = (self.last_side?, self.last_seen?);
        if duration <= 0.0 || time - seen > grace {
            return None;
        }
        self.pivot = Some((time, side));
        Some(side)
    }

    /// In place, toward `side` at `rate` rad/s.
    pub fn command(side: Side, rate: f32, wheel_base: f32) -> WheelCommand {
        let half = 0.5 * rate * wheel_base * side.sign();
        WheelCommand::new(-half, half)
    }
}
