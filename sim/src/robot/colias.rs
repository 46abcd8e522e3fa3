//! Physical parameters of a Colias micro-robot.
use serde::{Deserialize, Serialize};

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ColiasParams {
    /// Body radius, m (4 cm diameter).
    pub radius: f32,
    /// kg.
    pub mass: f32,
    /// Distance between the wheels, m.
    pub wheel_base: f32,
    /// Largest wheel surface speed, m/s.
    pub max_wheel_speed: f32,
    /// First-order motor time constant, s.
    pub motor_lag: f32,
}

impl Default for ColiasParams {
    fn default() -> Self {
        ColiasParams {
            radius: 0.02,
            mass: 0.05,
            wheel_base: 0.026,
            max_wheel_speed: 0.35,
            motor_lag: 0.05,
        }
    }
}
