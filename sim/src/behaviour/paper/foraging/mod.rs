//! Algorithm 1: ant foraging with three pheromones (paper, case I).
//!
//! The trails are drawn in three colours: LAP (long-term attractive, blue) on every trail, SAP
//! (short-term attractive, green) on the branches to the available food, so those look cyan, and SRP
//! (short-term repellent, red) at the start of the unrewarding branches of a bifurcation, which look
//! magenta. The robot:
//!
//! 1. avoids (a sharp pivot) on a bumper hit;
//! 2. when no sensor sees the LAP: right after losing it, pivots toward the side it was last seen on
//!    (`recover_turn`, [`Recovery`]: a bend sharper than the robot can steer, as drawn trails have, throws
//!    it off the outer edge); otherwise wanders (correlated random walk);
//! 3. at a bifurcation, picks a branch (below) and keeps to it for `commit_time` seconds;
//! 4. otherwise follows the cyan trail (eq. 7 on the green channel) when any sensor sees cyan, else the
//!    blue trail (eq. 7 on the blue channel), with a damping term (`damping`, see [`ForagingParams`]).
//!
//! ## What a sensor sees
//!
//! Each sensor's calibrated intensities are thresholded at `threshold` into a [`TrailClass`]: `Off`
//! (blue below threshold), `Magenta` (blue and red), `Cyan` (blue and green) or `Blue` (blue only).
//!
//! ## Bifurcation detection (the paper does not say how; this is our definition)
//!
//! A bifurcation is where the left (`n = 2`) and right (`n = 0`) sensors are both on the LAP and either
//!
//! * the front sensor (`n = 1`) is off the LAP: the robot straddles the wedge between two branches that
//!   leave the fork at a clear angle (the trail maps use symmetric forks of +-35 degrees, so for a robot
//!   within about a centimetre of the trail's centre line this pattern lasts 2-3 cm of travel), or
//! * one of the left and right sensors sees cyan and the other does not (blue or magenta), which
//!   happens a little earlier on the maps with SAP or SRP. (Blue on one side and magenta on the other
//!   with the front on the trail is a robot entering an SRP piece at an angle, not a fork.)
//!
//! Its kind ([`BifurcationKind`]) and the branch taken ([`Side`]):
//!
//! * `Magenta`: a side or the front sees magenta (the SRP piece starts 3 cm into its branch, where the
//!   front sensor may reach it before the side sensor over that branch does). Take the side whose sensor reads more `green - red` (the cyan
//!   branch; a coin decides a tie). Algorithm 1: "follow the cyan trail" at an LAP/SRP bifurcation.
//! * `CyanBlue`: one side cyan, the other blue. Take the cyan side with probability
//!   `cyan_probability` (0.7), the blue one otherwise (Algorithm 1).
//! * `Plain`: both sides the same colour (every bifurcation with the LAP alone): a fair coin. Algorithm 1
//!   only says "follow the LAP" there; with one trail colour a coin is the unbiased reading.
//!
//! After the decision the robot commits to the chosen branch for `commit_time` seconds. Keeping to the
//! cyan trail at a cyan/blue or magenta bifurcation needs nothing more (following the green channel
//! already keeps the robot on the cyan branch, the blue one being invisible in green). Any other choice
//! (the blue branch, or either branch of a plain bifurcation) is made in two steps: first it turns
//! toward the chosen side on an arc, at `turn_rate` rad/s and `commit_speed` times the base speed, for
//! as long as it takes to turn by `turn_angle` degrees (the fork's half-angle: this points it along the
//! chosen branch; a robot knows its own wheel commands, nothing more is needed), then it follows the
//! outer edge of the chosen branch: eq. (7) with the sensor on the other side (which may lie over the
//! gap between the branches, or over the other branch) replaced by the front sensor, on the chosen
//! trail's signal (cyan: green; blue-only: `blue - green`; LAP: blue). It goes straight while both see
//! the trail, turns away from the chosen side when that sensor leaves the trail and toward it when the
//! front sensor does. No new bifurcation is detected while committed.
mod bifurcation;
mod params;
mod recovery;

pub use bifurcation::{BifurcationKind, Side, Trail, TrailClass, detect_bifurcation};
pub use params::ForagingParams;
pub use recovery::Recovery;

use super::{BLUE, GREEN, RED, SENSOR_FRONT, SENSOR_LEFT, SENSOR_RIGHT, eq7};
use crate::behaviour::{Avoid, Behaviour, Observation, Wander, WheelCommand};
use crate::rng::SimRng;
use rand::RngExt;

/// A pivot to recover a lost trail starts only this soon after it was last seen (a few control
/// steps), s.
const RECOVER_GRACE: f32 = 0.2;

/// The branch of Algorithm 1 taken in one control step.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ForagingDecision {
    /// A bumper fired (or a pivot is under way).
    Avoid,
    /// No sensor on the LAP.
    Wander,
    /// On the LAP only: eq. (7) on blue.
    FollowLap,
    /// On the cyan trail: eq. (7) on green.
    FollowCyan,
    /// A bifurcation was detected now and `side` chosen.
    Bifurcation {
        kind: BifurcationKind,
        side: Side,
        trail: Trail,
    },
    /// Turning into the branch chosen at a recent bifurcation.
    TurnInto { side: Side, trail: Trail },
    /// Following the branch chosen at a recent bifurcation (no new bifurcation is detected).
    Committed { side: Side, trail: Trail },
    /// Every sensor has just left the LAP, or the cyan trail it was following: pivoting toward the side
    /// it was last seen on.
    Recover { side: Side },
}

#[derive(Clone, Copy, Debug, PartialEq)]
struct Commit {
    /// End of the turn into the branch, s.
    turn_until: f32,
    until: f32,
    side: Side,
    trail: Trail,
}

/// Algorithm 1 as a behaviour (registered as `forage`).
pub struct Foraging {
    pub params: ForagingParams,
    /// The robot's wheel base, m (to turn at a given yaw rate): the Colias default, or the scenario's
    /// `[robot] wheel_base` when built from a scenario.
    pub wheel_base: f32,
    avoid: Avoid<Wander>,
    commit: Option<Commit>,
    recovery: Recovery,
    /// (time, e) of the previous trail-following step, for the damping term.
    last_error: Option<(f32, f32)>,
}

impl Foraging {
    pub fn new(params: ForagingParams) -> Self {
        let avoid = Avoid::new(Wander::new(params.speed));
        Foraging {
            params,
            wheel_base: crate::robot::ColiasParams::default().wheel_base,
            avoid,
            commit: None,
            recovery: Recovery::default(),
            last_error: None,
        }
    }

    /// True while the robot keeps to a chosen branch at `time`.
    pub fn committed(&self, time: f32) -> bool {
        self.commit.is_some_and(|c| time < c.until)
    }

    fn coin(rng: &mut SimRng) -> Side {
        if rng.random::<f32>() < 0.5 {
            Side::Left
        } else {
            Side::Right
        }
    }

    /// The branch to take at a bifurcation of `kind`, and the trail to steer on.
    pub fn choose(
        &self,
        kind: BifurcationKind,
        obs: &Observation,
        rng: &mut SimRng,
    ) -> (Side, Trail) {
        let th = self.params.threshold;
        let (l, r) = (obs.intensity[SENSOR_LEFT], obs.intensity[SENSOR_RIGHT]);
        let trail_of = |rgb: [f32; 3]| {
            if TrailClass::of(rgb, th) == TrailClass::Cyan {
                Trail::Cyan
            } else {
                Trail::Lap
            }
        };
        match kind {
            BifurcationKind::Magenta => {
                let score = |rgb: [f32; 3]| rgb[GREEN] - rgb[RED];
                let side = match score(l).partial_cmp(&score(r)) {
                    Some(std::cmp::Ordering::Greater) => Side::Left,
                    Some(std::cmp::Ordering::Less) => Side::Right,
                    _ => Self::coin(rng),
                };
                (side, trail_of(if side == Side::Left { l } else { r }))
            }
            BifurcationKind::CyanBlue => {
                let cyan_side = if TrailClass::of(l, th) == TrailClass::Cyan {
                    Side::Left
                } else {
                    Side::Right
                };
                if rng.random::<f32>() < self.params.cyan_probability {
                    (cyan_side, Trail::Cyan)
                } else {
                    let blue_side = if cyan_side == Side::Left {
                        Side::Right
                    } else {
                        Side::Left
                    };
                    (blue_side, Trail::BlueOnly)
                }
            }
            BifurcationKind::Plain => {
                let side = Self::coin(rng);
                (side, trail_of(if side == Side::Left { l } else { r }))
            }
        }
    }

    /// Algorithm 1: which branch applies now. Updates the commitment state (and draws from `rng` at a
    /// bifurcation).
    pub fn decide(&mut self, obs: &Observation, rng: &mut SimRng) -> ForagingDecision {
        if self.avoid.turning(obs.time) || obs.max_bumper() > self.avoid.threshold {
            self.recovery.forget();
            return ForagingDecision::Avoid;
        }
        let p = &self.params;
        let th = p.threshold;
        if !obs.intensity.iter().any(|s| s[BLUE] > th) {
            self.commit = None;
            // A pivot starts only right after the trail was lost (within a few control steps).
            return match self.recovery.lap.pivot_side(
                obs.time,
                p.recover_turn,
                p.recover_rate,
                RECOVER_GRACE,
            ) {
                Some(side) => ForagingDecision::Recover { side },
                None => ForagingDecision::Wander,
            };
        }
        self.recovery.on_trail(obs);
        let sees_cyan = obs
            .intensity
            .iter()
            .any(|&s| TrailClass::of(s, th) == TrailClass::Cyan);
        if sees_cyan && self.commit.is_none_or(|c| c.trail == Trail::Cyan) {
            self.recovery.on_cyan(obs);
        }
        if let Some(c) = self.commit {
            if obs.time < c.turn_until {
                return ForagingDecision::TurnInto {
                    side: c.side,
                    trail: c.trail,
                };
            }
            if obs.time < c.until {
                return ForagingDecision::Committed {
                    side: c.side,
                    trail: c.trail,
                };
            }
            self.commit = None;
        }
        if !sees_cyan
            && let Some(side) = self.recovery.cyan.pivot_side(
                obs.time,
                p.recover_turn,
                p.recover_rate,
                RECOVER_GRACE,
            )
        {
            return ForagingDecision::Recover { side };
        }
        if let Some(kind) = detect_bifurcation(obs, th) {
            let (side, trail) = self.choose(kind, obs, rng);
            // Staying on the cyan trail needs no turn: following the green channel already keeps the
            // robot on the cyan branch. Any other choice turns into the chosen branch first.
            let stays_cyan = trail == Trail::Cyan && kind != BifurcationKind::Plain;
            let turn = if stays_cyan {
                0.0
            } else {
                self.params.turn_angle.to_radians() / self.params.turn_rate
            };
            if trail != Trail::Cyan {
                // Leaving the cyan trail on purpose: it is not lost.
                self.recovery.cyan.forget();
            }
            self.commit = Some(Commit {
                turn_until: obs.time + turn,
                until: obs.time + turn.max(self.params.commit_time),
                side,
                trail,
            });
            return ForagingDecision::Bifurcation { kind, side, trail };
        }
        if sees_cyan {
            ForagingDecision::FollowCyan
        } else {
            ForagingDecision::FollowLap
        }
    }

    /// Eq. (7) on `trail` (without the damping term: see [`Foraging::follow`]).
    pub fn steer(&self, obs: &Observation, trail: Trail) -> WheelCommand {
        let p = &self.params;
        let (l, r) = (
            trail.signal(obs.intensity[SENSOR_LEFT]),
            trail.signal(obs.intensity[SENSOR_RIGHT]),
        );
        eq7(l, r, p.sensitivity, p.speed)
    }

    /// Eq. (7) on `trail` with the damping term: `e + damping * de/dt` in place of `Phi_l - Phi_r`.
    pub fn follow(&mut self, obs: &Observation, trail: Trail) -> WheelCommand {
        let p = &self.params;
        let e =
            trail.signal(obs.intensity[SENSOR_LEFT]) - trail.signal(obs.intensity[SENSOR_RIGHT]);
        let rate = match self.last_error {
            Some((t, e0)) if obs.time > t && obs.time - t < 0.2 => (e - e0) / (obs.time - t),
            _ => 0.0,
        };
        self.last_error = Some((obs.time, e));
        eq7(e + p.damping * rate, 0.0, p.sensitivity, p.speed)
    }

    /// Eq. (7) between the sensor on `side` and the front sensor (see the module documentation).
    pub fn steer_committed(&self, obs: &Observation, trail: Trail, side: Side) -> WheelCommand {
        let p = &self.params;
        let n = if side == Side::Left {
            SENSOR_LEFT
        } else {
            SENSOR_RIGHT
        };
        let (outer, front) = (
            trail.signal(obs.intensity[n]),
            trail.signal(obs.intensity[SENSOR_FRONT]),
        );
        match side {
            Side::Left => eq7(outer, front, p.sensitivity, p.speed),
            Side::Right => eq7(front, outer, p.sensitivity, p.speed),
        }
    }

    /// The arc into the branch on `side`: forward at `commit_speed * speed`, yaw `turn_rate` toward it.
    pub fn turn_into(&self, side: Side, wheel_base: f32) -> WheelCommand {
        let p = &self.params;
        let v = p.commit_speed * p.speed;
        let half = 0.5 * p.turn_rate * wheel_base * side.sign();
        WheelCommand::new(v - half, v + half)
    }
}

impl Behaviour for Foraging {
    fn name(&self) -> &str {
        "forage"
    }
    fn act(&mut self, obs: &Observation, rng: &mut SimRng) -> WheelCommand {
        match self.decide(obs, rng) {
            // The avoid wrapper pivots on a bumper hit and wanders otherwise.
            ForagingDecision::Avoid | ForagingDecision::Wander => self.avoid.act(obs, rng),
            ForagingDecision::FollowLap => self.follow(obs, Trail::Lap),
            ForagingDecision::FollowCyan => self.follow(obs, Trail::Cyan),
            ForagingDecision::Bifurcation { side, .. }
            | ForagingDecision::TurnInto { side, .. } => self.turn_into(side, self.wheel_base),
            ForagingDecision::Committed { trail, side } => self.steer_committed(obs, trail, side),
            ForagingDecision::Recover { side } => {
                Recovery::command(side, self.params.recover_rate, self.wheel_base)
            }
        }
    }
}
