//! The parameters of `forage` (Algorithm 1), their documentation and validation.
use super::super::check;
use crate::behaviour::registry::ParamDoc;
use crate::error::Result;
use serde::{Deserialize, Serialize};

/// Parameters of [`Foraging`] as written in a scenario's `params` table.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ForagingParams {
    /// Base speed `v_b` of eq. (7), also the wandering speed, m/s.
    pub speed: f32,
    /// Sensitivity `p` of eq. (7): wheel speed difference per unit of left-right intensity difference, m/s.
    pub sensitivity: f32,
    /// Calibrated intensity (0..1) above which a sensor counts as on a pheromone.
    pub threshold: f32,
    /// Probability of following the cyan branch at a cyan/blue bifurcation (paper: 0.7).
    pub cyan_probability: f32,
    /// How long the robot keeps to the branch it chose, s.
    pub commit_time: f32,
    /// Damping time of the trail following, s: eq. (7) acts on `e + damping * de/dt` with
    /// `e = Phi_l - Phi_r` (0: eq. 7 as printed). The left and right sensors sit on the wheel axis, so
    /// eq. (7) alone steers on the lateral offset only and lets the robot swing across the trail; the
    /// rate of change of `e` adds the missing damping.
    pub damping: f32,
    /// Angle of the turn into the chosen branch, degrees.
    pub turn_angle: f32,
    /// Yaw rate of that turn, rad/s.
    pub turn_rate: f32,
    /// Forward speed during that turn, as a fraction of `speed`.
    pub commit_speed: f32,
    /// On losing the trail, pivot toward the side last seen by up to this angle, degrees (0: wander
    /// at once, as Algorithm 1 as printed).
    pub recover_turn: f32,
    /// Yaw rate of that pivot, rad/s.
    pub recover_rate: f32,
}

impl Default for ForagingParams {
    fn default() -> Self {
        ForagingParams {
            speed: 0.1,
            sensitivity: 0.03,
            threshold: 0.3,
            cyan_probability: 0.7,
            commit_time: 1.0,
            damping: 0.3,
            turn_angle: 35.0,
            turn_rate: 3.0,
            commit_speed: 0.5,
            recover_turn: 120.0,
            recover_rate: 3.0,
        }
    }
}

impl ForagingParams {
    /// Every key of the `params` table of `forage`, as `colcos behaviours` prints it.
    pub const DOCS: &'static [ParamDoc] = &[
        ParamDoc {
            name: "speed",
            ty: "float, m/s, >= 0",
            default: "0.1",
            meaning: "base speed v_b of eq. (7), also the wandering speed",
        },
        ParamDoc {
            name: "sensitivity",
            ty: "float, m/s, >= 0",
            default: "0.03",
            meaning: "p of eq. (7): wheel speed difference per unit of left-right intensity difference",
        },
        ParamDoc {
            name: "threshold",
            ty: "float, 0..1, >= 0",
            default: "0.3",
            meaning: "calibrated intensity above which a sensor counts as on a pheromone",
        },
        ParamDoc {
            name: "cyan_probability",
            ty: "float, 0..=1",
            default: "0.7",
            meaning: "probability of taking the cyan branch at a cyan/blue bifurcation",
        },
        ParamDoc {
            name: "commit_time",
            ty: "float, s, >= 0",
            default: "1.0",
            meaning: "how long the robot keeps to the branch it chose",
        },
        ParamDoc {
            name: "damping",
            ty: "float, s, >= 0",
            default: "0.3",
            meaning: "eq. (7) acts on e + damping * de/dt (0: eq. (7) as printed)",
        },
        ParamDoc {
            name: "turn_angle",
            ty: "float, degrees, >= 0",
            default: "35.0",
            meaning: "angle of the turn into the chosen branch (the fork's half-angle)",
        },
        ParamDoc {
            name: "turn_rate",
            ty: "float, rad/s, >= 0.001",
            default: "3.0",
            meaning: "yaw rate of that turn",
        },
        ParamDoc {
            name: "commit_speed",
            ty: "float, >= 0",
            default: "0.5",
            meaning: "forward speed during that turn, as a fraction of speed",
        },
        ParamDoc {
            name: "recover_turn",
            ty: "float, degrees, >= 0",
            default: "120.0",
            meaning: "on losing the trail, pivot toward the side last seen by up to this angle (0: wander at once)",
        },
        ParamDoc {
            name: "recover_rate",
            ty: "float, rad/s, >= 0.001",
            default: "3.0",
            meaning: "yaw rate of that pivot",
        },
    ];

    /// Checks every value; `key` is the scenario key path of the group (for errors).
    pub fn validate(&self, key: &str) -> Result<()> {
        check(key, "speed", self.speed, 0.0)?;
        check(key, "sensitivity", self.sensitivity, 0.0)?;
        check(key, "threshold", self.threshold, 0.0)?;
        check(key, "commit_time", self.commit_time, 0.0)?;
        check(key, "damping", self.damping, 0.0)?;
        check(key, "turn_angle", self.turn_angle, 0.0)?;
        check(key, "turn_rate", self.turn_rate, 1e-3)?;
        check(key, "commit_speed", self.commit_speed, 0.0)?;
        check(key, "recover_turn", self.recover_turn, 0.0)?;
        check(key, "recover_rate", self.recover_rate, 1e-3)?;
        if !(0.0..=1.0).contains(&self.cyan_probability) {
            return Err(crate::error::SimError::invalid(
                format!("{key}.params.cyan_probability"),
                self.cyan_probability,
                "must be a probability in [0, 1]",
            ));
        }
        Ok(())
    }
}
