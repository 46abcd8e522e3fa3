//! Recovering a lost trail. A robot that follows a trail into a bend sharper than it can steer (a
//! branch curving away right after its fork, a polyline's corner) runs off its outer edge; wandering
//! from there rarely finds the trail again. So when every sensor has just left the LAP, the robot
//! pivots in place toward the side where its sensors last saw more of it, by up to `recover_turn`
//! degrees at `recover_rate` rad/s; it takes up the trail as soon as any sensor sees the LAP again, and
//! wanders only if the pivot found nothing. Likewise a robot following the cyan trail (LAP + SAP) that
//! runs off a bend onto the blue or magenta of another branch pivots toward the side where it last saw
//! cyan before it follows anything else (a deliberate turn onto a blue branch at a bifurcation forgets
//! the cyan first). All it uses is its own left and right sensors' past readings and the clock.
use super::super::{BLUE, GREEN, SENSOR_LEFT, SENSOR_RIGHT};
use super::Side;
use crate::behaviour::{Observation, WheelCommand};

/// What the robot remembers of one trail: where its sensors last saw it, and the pivot under way.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Memory {
    /// The side on which the left and right sensors last saw more of it.
    last_side: Option<Side>,
    /// When a sensor last saw it, s.
    last_seen: Option<f32>,
    /// Start of the pivot under way, and its side.
    pivot: Option<(f32, Side)>,
    /// Start of the last pivot, s (kept when the trail is forgotten).
    last_pivot: Option<f32>,
}

/// No pivot starts sooner than this after the last one began, s: a robot that keeps losing the trail
/// at one place (the wedge of a fork it missed, a trail end) wanders off instead of pivoting for ever.
const COOLDOWN: f32 = 2.0;

impl Memory {
    /// Notes a step on the trail, whose signal at the left and right sensors is `l` and `r`.
    pub fn seen(&mut self, time: f32, l: f32, r: f32) {
        if l > r {
            self.last_side = Some(Side::Left);
        } else if r > l {
            self.last_side = Some(Side::Right);
        }
        self.last_seen = Some(time);
        self.pivot = None;
    }

    pub fn forget(&mut self) {
        *self = Memory {
            last_pivot: self.last_pivot,
            ..Memory::default()
        };
    }

    /// With the trail out of sight at `time`: the side to pivot toward, while a pivot of `turn_deg` at
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
        let cooling = self.last_pivot.is_some_and(|t| time - t < COOLDOWN);
        if duration <= 0.0 || time - seen > grace || cooling {
            return None;
        }
        self.pivot = Some((time, side));
        self.last_pivot = Some(time);
        Some(side)
    }
}

/// What the robot remembers of the LAP and of the cyan trail it was following.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Recovery {
    pub lap: Memory,
    pub cyan: Memory,
}

impl Recovery {
    /// Notes a step with a sensor on the LAP (blue channel).
    pub fn on_trail(&mut self, obs: &Observation) {
        let (l, r) = (obs.intensity[SENSOR_LEFT], obs.intensity[SENSOR_RIGHT]);
        self.lap.seen(obs.time, l[BLUE], r[BLUE]);
    }

    /// Notes a step following the cyan trail (green channel).
    pub fn on_cyan(&mut self, obs: &Observation) {
        let (l, r) = (obs.intensity[SENSOR_LEFT], obs.intensity[SENSOR_RIGHT]);
        self.cyan.seen(obs.time, l[GREEN], r[GREEN]);
    }

    /// Forgets both trails (after a bumper hit).
    pub fn forget(&mut self) {
        *self = Recovery::default();
    }

    /// In place, toward `side` at `rate` rad/s.
    pub fn command(side: Side, rate: f32, wheel_base: f32) -> WheelCommand {
        let half = 0.5 * rate * wheel_base * side.sign();
        WheelCommand::new(-half, half)
    }
}
