//! Hand-written policies of the tasks whose agents lay pheromone (`colony`, `coverage`, `alarm`):
//! each decides one agent's whole action, wheels and deposit rates, from that agent's observation
//! row alone (the 17 sensor values and the task's extra entries), exactly what a learned policy
//! sees. [`crate::baseline::BaselinePolicy`] runs them over a batch by name, as it runs the sim's
//! behaviours.
//!
//! They read the observation's sensor values as encoded by [`crate::encoding`]: sensors right (0),
//! front (1), left (2), back (3), three channels each, then the three bumpers.
mod alarm_flee;
mod colony_ant;
mod coverage_walk;

use colcos_sim::rng::{SimRng, normal};

/// One agent's policy over its observation row.
pub trait AgentPolicy: Send {
    /// Writes the continuous action `out` (`[left, right, rate_0, ..]`: wheels in `[-1, 1]`, rates
    /// in `[0, 1]`) for observation row `obs`. `rng` is the agent's own stream.
    fn act(&mut self, obs: &[f32], rng: &mut SimRng, out: &mut [f32]);
}

/// Every policy: name, the task it is written for, what it does.
pub const POLICIES: &[(&str, &str, &str)] = &[
    (
        "colony_ant",
        "colony",
        "the two-pheromone ant rule: lay home while searching, food while loaded; follow the other",
    ),
    (
        "coverage_walk",
        "coverage",
        "a random walk that lays visited and turns away from it",
    ),
    (
        "alarm_flee",
        "alarm",
        "lay alarm while the predator is near, flee down the alarm's gradient, else keep still",
    ),
];

/// Policy `name`, new (its per-agent memory empty), or None if there is none of that name.
pub fn build(name: &str) -> Option<Box<dyn AgentPolicy>> {
    Some(match name {
        "colony_ant" => Box::new(colony_ant::ColonyAnt::default()),
        "coverage_walk" => Box::new(coverage_walk::CoverageWalk::default()),
        "alarm_flee" => Box::new(alarm_flee::AlarmFlee::default()),
        _ => return None,
    })
}

/// The hand-written policy written for task `task`, if any.
pub fn for_task(task: &str) -> Option<&'static str> {
    POLICIES.iter().find(|p| p.1 == task).map(|p| p.0)
}

/// Sensor `s` (0 right, 1 front, 2 left, 3 back), channel `c` of an observation row.
fn level(obs: &[f32], s: usize, c: usize) -> f32 {
    obs[3 * s + c]
}

/// Mean of the four sensors in channel `c`.
fn strength(obs: &[f32], c: usize) -> f32 {
    (0..4).map(|s| level(obs, s, c)).sum::<f32>() / 4.0
}

/// Egocentric direction of the rising gradient of channel `c`, rad counter-clockwise from ahead
/// (the paper's eq. (6)).
fn gradient_angle(obs: &[f32], c: usize) -> f32 {
    (level(obs, 2, c) - level(obs, 0, c)).atan2(level(obs, 1, c) - level(obs, 3, c))
}

/// Egocentric direction of the falling gradient of channel `c`: away from its source.
fn down_gradient_angle(obs: &[f32], c: usize) -> f32 {
    let up = gradient_angle(obs, c);
    up - up.signum() * std::f32::consts::PI
}

/// Wheels (fractions) driving at `speed` while turning toward egocentric angle `angle`.
fn steer(speed: f32, angle: f32, gain: f32) -> (f32, f32) {
    let turn = (gain * angle).clamp(-0.3, 0.3);
    (speed - turn, speed + turn)
}

/// A correlated random walk that pivots away from what its bumpers feel. Shared by the policies:
/// the motion each falls back on when its pheromones say nothing.
#[derive(Default)]
struct Walker {
    /// Current turn (wheel difference, fraction of the top speed).
    turn: f32,
    /// Steps of a pivot still to go, and its sign (+1 counter-clockwise).
    pivot: u32,
    sign: f32,
    /// The forward part of the last wheels asked for (fraction of the top speed).
    asked: f32,
}

/// Bumper reading above which the walker pivots away.
const BUMP: f32 = 0.2;
/// Steps of a pivot away from a bump (about 60 degrees at the pivot speed).
const BUMP_PIVOT: u32 = 10;
/// Wheel speed of a pivot, fraction of the top speed.
const PIVOT_SPEED: f32 = 0.2;

impl Walker {
    /// Starts a pivot of `steps` steps in direction `sign`.
    fn start_pivot(&mut self, steps: u32, sign: f32) {
        self.pivot = steps;
        self.sign = sign;
    }

    /// The pivot in progress, or one started by a bump or by the safety shield's virtual wall (the
    /// last command sent had no forward part where one was asked for): None if the robot is free
    /// to go on.
    fn avoid(&mut self, obs: &[f32]) -> Option<(f32, f32)> {
        if self.pivot == 0 && obs[12..15].iter().any(|&b| b > BUMP) {
            // More on the front-left: turn clockwise.
            let sign = if obs[12] > obs[14] { -1.0 } else { 1.0 };
            self.start_pivot(BUMP_PIVOT, sign);
        } else if self.pivot == 0 && self.asked > 0.1 && 0.5 * (obs[15] + obs[16]) < 0.02 {
            self.start_pivot(2 * BUMP_PIVOT, 1.0);
        }
        (self.pivot > 0).then(|| {
            self.pivot -= 1;
            (-PIVOT_SPEED * self.sign, PIVOT_SPEED * self.sign)
        })
    }

    /// Hands back the wheels `(l, r)` a policy chose, remembering how much forward it asked for.
    fn drive(&mut self, (l, r): (f32, f32)) -> (f32, f32) {
        self.asked = 0.5 * (l + r);
        (l, r)
    }

    /// One step of the random walk at `speed`.
    fn walk(&mut self, speed: f32, rng: &mut SimRng) -> (f32, f32) {
        self.turn = (0.9 * self.turn + 0.01 * normal(rng)).clamp(-0.05, 0.05);
        (speed - self.turn, speed + self.turn)
    }
}
