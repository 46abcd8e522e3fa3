//! The paper's controllers: Algorithm 1 (ant foraging with three pheromones, steering by eq. 7) and
//! Algorithms 2 and 3 (leader and follower under aggregation and alarm pheromones, steering by eq. 8).
//!
//! Like every behaviour they see only their own [`Observation`]: four colour sensors (`n = 0..3` at the
//! robot-frame `Y-` right, `X+` front, `Y+` left, `X-` back), three bumpers and the clock.
//!
//! ## Sign conventions (documented choices where the paper is loose)
//!
//! * **Eq. (7)** is printed as `R_l = (Phi_l - Phi_r) p + v_b`, `R_r = (Phi_r - Phi_l) p + v_b`. For a
//!   differential drive that speeds up the wheel on the side that sees *more* pheromone, which turns the
//!   robot *away* from the trail (a right turn when the left sensor is on the trail). We use the sign
//!   that follows the trail: `R_l = v_b - p (Phi_l - Phi_r)`, `R_r = v_b + p (Phi_l - Phi_r)`
//!   ([`eq7`]); the left sensor is `n = 2` (`Y+`), the right one `n = 0` (`Y-`).
//! * **Eq. (8)**, `R_l = v_b - p (theta_g - theta_r)`, `R_r = v_b + p (theta_g - theta_r)`, already has
//!   the right sign for egocentric angles measured counter-clockwise from forward (eq. 6): a positive
//!   angle speeds up the right wheel and turns the robot left, toward it. Algorithms 2 and 3 use one
//!   pheromone at a time, so [`eq8`] takes one desired direction: the AGP gradient `theta_g` to approach,
//!   and `wrap(theta_r + pi)`, straight down the ALP gradient, to flee. The latter has the sign of the
//!   printed `-p theta_r` for every `theta_r` in `(-pi, pi)` and no dead point when the alarm is behind.

pub mod aggregation;
pub mod foraging;

pub use aggregation::{
    AggregationDecision, AggregationParams, Follower, FollowerParams, Leader, LeaderParams,
};
pub use foraging::{
    BifurcationKind, Foraging, ForagingDecision, ForagingParams, Recovery, Side, Trail, TrailClass,
    detect_bifurcation,
};

use super::WheelCommand;

/// Index of the right colour sensor (`Y-`).
pub const SENSOR_RIGHT: usize = 0;
/// Index of the front colour sensor (`X+`).
pub const SENSOR_FRONT: usize = 1;
/// Index of the left colour sensor (`Y+`).
pub const SENSOR_LEFT: usize = 2;
/// Index of the back colour sensor (`X-`).
pub const SENSOR_BACK: usize = 3;

/// Channel of the red pheromone (SRP in case I, ALP in case II).
pub const RED: usize = 0;
/// Channel of the green pheromone (SAP in case I, AGP in case II).
pub const GREEN: usize = 1;
/// Channel of the blue pheromone (LAP in case I).
pub const BLUE: usize = 2;

/// Eq. (7) with the trail-following sign: wheel speeds (m/s) from the left and right sensors' readings
/// of the followed pheromone, the sensitivity `p` (m/s per unit of intensity) and the base speed `v_b`.
pub fn eq7(phi_left: f32, phi_right: f32, p: f32, v_b: f32) -> WheelCommand {
    let turn = p * (phi_left - phi_right);
    WheelCommand::new(v_b - turn, v_b + turn)
}

/// Eq. (8): wheel speeds that turn the robot toward the egocentric `direction` (rad, counter-clockwise
/// from forward, wrapped into `(-pi, pi]`), with sensitivity `p` (m/s per rad) and base speed `v_b`.
pub fn eq8(direction: f32, p: f32, v_b: f32) -> WheelCommand {
    let d = crate::angle::wrap_pi(direction);
    WheelCommand::new(v_b - p * d, v_b + p * d)
}

/// Checks that a parameter is finite and at least `min`.
pub(crate) fn check(key: &str, name: &str, value: f32, min: f32) -> crate::error::Result<()> {
    if value.is_finite() && value >= min {
        Ok(())
    } else {
        Err(crate::error::SimError::invalid(
            format!("{key}.params.{name}"),
            value,
            format!("must be a finite number >= {min}"),
        ))
    }
}
