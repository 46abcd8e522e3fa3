//! Algorithms 2 (leader) and 3 (follower): aggregation and alarm pheromones (paper, case II).
//!
//! The leader carries the aggregation pheromone (AGP, green, a Gaussian source that follows it); any robot
//! close to the predator releases the alarm pheromone (ALP, red). Both are emitted by the world (the
//! scenario's `emits`), not by the behaviours: a behaviour only senses them.
//!
//! * Leader (Algorithm 2): on a bumper hit, avoid; else if it senses ALP (mean red intensity above
//!   `alarm_threshold`), flee down the ALP gradient with eq. (8); else wander.
//! * Follower (Algorithm 3): on a bumper hit, avoid; else if it senses ALP, flee down the ALP gradient;
//!   else if it senses AGP (mean green intensity above `attract_threshold`), go up the AGP gradient with
//!   eq. (8); else wander.
//!
//! Directions come from eq. (6) ([`Observation::gradient_direction`]); see the parent module for the
//! sign of eq. (8).
use super::{GREEN, RED, check, eq8};
use crate::angle::wrap_pi;
use crate::behaviour::param_doc::ParamDoc;
use crate::behaviour::{Avoid, Behaviour, Observation, Wander, WheelCommand};
use crate::error::Result;
use crate::rng::SimRng;
use serde::{Deserialize, Serialize};

/// Parameters of the leader ([`Leader`], registered as `aggregation_leader`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct LeaderParams {
    /// Base speed `v_b` of eq. (8) when fleeing, m/s.
    pub speed: f32,
    /// Wandering speed, m/s.
    pub wander_speed: f32,
    /// Sensitivity `p` of eq. (8), m/s per rad.
    pub sensitivity: f32,
    /// Mean red intensity (0..1) above which the robot senses the ALP.
    pub alarm_threshold: f32,
}

impl Default for LeaderParams {
    fn default() -> Self {
        LeaderParams {
            speed: 0.1,
            wander_speed: 0.03,
            sensitivity: 0.03,
            alarm_threshold: 0.05,
        }
    }
}

/// Parameters of a follower ([`Follower`], registered as `aggregation_follower`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FollowerParams {
    /// Base speed `v_b` of eq. (8), m/s.
    pub speed: f32,
    /// Wandering speed, m/s.
    pub wander_speed: f32,
    /// Sensitivity `p` of eq. (8), m/s per rad.
    pub sensitivity: f32,
    /// Mean red intensity (0..1) above which the robot senses the ALP.
    pub alarm_threshold: f32,
    /// Mean green intensity (0..1) above which the robot senses the AGP.
    pub attract_threshold: f32,
}

impl Default for FollowerParams {
    fn default() -> Self {
        FollowerParams {
            speed: 0.08,
            wander_speed: 0.05,
            sensitivity: 0.03,
            alarm_threshold: 0.05,
            attract_threshold: 0.01,
        }
    }
}

/// The `sensitivity` key, alike for leaders and followers.
const SENSITIVITY_DOC: ParamDoc = ParamDoc {
    name: "sensitivity",
    ty: "float, m/s per rad, >= 0",
    default: "0.03",
    meaning: "p of eq. (8)",
};

/// The `alarm_threshold` key, alike for leaders and followers.
const ALARM_THRESHOLD_DOC: ParamDoc = ParamDoc {
    name: "alarm_threshold",
    ty: "float, 0..1, >= 0",
    default: "0.05",
    meaning: "mean red intensity above which the robot senses the ALP and flees it",
};

/// The shared parameters of both algorithms.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AggregationParams {
    pub speed: f32,
    pub wander_speed: f32,
    pub sensitivity: f32,
    pub alarm_threshold: f32,
    /// `f32::INFINITY` for the leader (it ignores the AGP).
    pub attract_threshold: f32,
}

impl LeaderParams {
    /// Every key of the `params` table of `aggregation_leader`, as `colcos behaviours` prints it.
    pub const DOCS: &'static [ParamDoc] = &[
        ParamDoc {
            name: "speed",
            ty: "float, m/s, >= 0",
            default: "0.1",
            meaning: "base speed v_b of eq. (8) when fleeing",
        },
        ParamDoc {
            name: "wander_speed",
            ty: "float, m/s, >= 0",
            default: "0.03",
            meaning: "wandering speed",
        },
        SENSITIVITY_DOC,
        ALARM_THRESHOLD_DOC,
    ];

    pub fn validate(&self, key: &str) -> Result<AggregationParams> {
        check(key, "speed", self.speed, 0.0)?;
        check(key, "wander_speed", self.wander_speed, 0.0)?;
        check(key, "sensitivity", self.sensitivity, 0.0)?;
        check(key, "alarm_threshold", self.alarm_threshold, 0.0)?;
        Ok(AggregationParams {
            speed: self.speed,
            wander_speed: self.wander_speed,
            sensitivity: self.sensitivity,
            alarm_threshold: self.alarm_threshold,
            attract_threshold: f32::INFINITY,
        })
    }
}

impl FollowerParams {
    /// Every key of the `params` table of `aggregation_follower`, as `colcos behaviours` prints it.
    pub const DOCS: &'static [ParamDoc] = &[
        ParamDoc {
            name: "speed",
            ty: "float, m/s, >= 0",
            default: "0.08",
            meaning: "base speed v_b of eq. (8)",
        },
        ParamDoc {
            name: "wander_speed",
            ty: "float, m/s, >= 0",
            default: "0.05",
            meaning: "wandering speed",
        },
        SENSITIVITY_DOC,
        ALARM_THRESHOLD_DOC,
        ParamDoc {
            name: "attract_threshold",
            ty: "float, 0..1, >= 0",
            default: "0.01",
            meaning: "mean green intensity above which the robot senses the AGP and climbs it",
        },
    ];

    pub fn validate(&self, key: &str) -> Result<AggregationParams> {
        // The leader's keys, checked as the leader's, then the follower's own.
        let leader = LeaderParams {
            speed: self.speed,
            wander_speed: self.wander_speed,
            sensitivity: self.sensitivity,
            alarm_threshold: self.alarm_threshold,
        };
        let params = leader.validate(key)?;
        check(key, "attract_threshold", self.attract_threshold, 0.0)?;
        Ok(AggregationParams {
            attract_threshold: self.attract_threshold,
            ..params
        })
    }
}

/// The branch of Algorithm 2 or 3 taken in one control step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum AggregationDecision {
    Avoid,
    /// ALP sensed: steer toward `direction` (egocentric rad), straight down the ALP gradient.
    Flee {
        direction: f32,
    },
    /// AGP sensed (followers only): steer toward `direction`, up the AGP gradient.
    Approach {
        direction: f32,
    },
    Wander,
}

/// Shared machinery of the two algorithms.
struct Core {
    params: AggregationParams,
    avoid: Avoid<Wander>,
}

impl Core {
    fn new(params: AggregationParams) -> Self {
        Core {
            params,
            avoid: Avoid::new(Wander::new(params.wander_speed)),
        }
    }

    fn decide(&self, obs: &Observation) -> AggregationDecision {
        if self.avoid.turning(obs.time) || obs.max_bumper() > self.avoid.threshold {
            return AggregationDecision::Avoid;
        }
        if obs.strength(RED) > self.params.alarm_threshold {
            let theta_r = obs.gradient_direction(RED);
            return AggregationDecision::Flee {
                direction: wrap_pi(theta_r + std::f32::consts::PI),
            };
        }
        if obs.strength(GREEN) > self.params.attract_threshold {
            return AggregationDecision::Approach {
                direction: obs.gradient_direction(GREEN),
            };
        }
        AggregationDecision::Wander
    }

    fn command(
        &mut self,
        decision: AggregationDecision,
        obs: &Observation,
        rng: &mut SimRng,
    ) -> WheelCommand {
        match decision {
            AggregationDecision::Avoid | AggregationDecision::Wander => self.avoid.act(obs, rng),
            AggregationDecision::Flee { direction }
            | AggregationDecision::Approach { direction } => {
                eq8(direction, self.params.sensitivity, self.params.speed)
            }
        }
    }
}

/// Algorithm 2: the leader.
pub struct Leader {
    core: Core,
}

impl Leader {
    pub fn new(params: AggregationParams) -> Self {
        Leader {
            core: Core::new(AggregationParams {
                attract_threshold: f32::INFINITY,
                ..params
            }),
        }
    }
}

/// Algorithm 3: a follower.
pub struct Follower {
    core: Core,
}

impl Follower {
    pub fn new(params: AggregationParams) -> Self {
        Follower {
            core: Core::new(params),
        }
    }
}

/// `decide` and [`Behaviour`] of an algorithm that runs [`Core`]: `$algorithm` names it in the docs,
/// `$name` is the name it is registered under.
macro_rules! runs_core {
    ($role:ident, $name:literal, $algorithm:literal) => {
        impl $role {
            #[doc = concat!("Which branch of ", $algorithm, " applies to `obs`.")]
            pub fn decide(&self, obs: &Observation) -> AggregationDecision {
                self.core.decide(obs)
            }
        }

        impl Behaviour for $role {
            fn name(&self) -> &str {
                $name
            }
            fn act(&mut self, obs: &Observation, rng: &mut SimRng) -> WheelCommand {
                let d = self.core.decide(obs);
                self.core.command(d, obs, rng)
            }
        }
    };
}

runs_core!(Leader, "aggregation_leader", "Algorithm 2");
runs_core!(Follower, "aggregation_follower", "Algorithm 3");
