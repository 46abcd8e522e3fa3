//! Differential drive with wheel-speed limits and first-order motor lag.
use super::ColiasParams;
use crate::behaviour::WheelCommand;

/// The actual wheel speeds, m/s, lagging behind the command.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct DriveState {
    pub left: f32,
    pub right: f32,
}

impl DriveState {
    /// Moves the wheel speeds toward the clamped command over `dt` (exact first-order response).
    pub fn update(&mut self, _cmd: WheelCommand, _params: &ColiasParams, _dt: f32) {
        todo!()
    }
    /// Body velocities: (forward speed m/s, yaw rate rad/s).
    pub fn body_velocity(&self, _params: &ColiasParams) -> (f32, f32) {
        todo!()
    }
}
