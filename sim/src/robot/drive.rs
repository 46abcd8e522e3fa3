//! Differential drive with wheel-speed limits and first-order motor lag.
use super::ColiasParams;
use crate::behaviour::WheelCommand;

/// The actual wheel speeds, m/s, lagging behind the command.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct DriveState {
    pub left: f32,
    pub right: f32,
}

/// A command component clamped to the wheel limit; NaN counts as 0.
fn clamp_command(v: f32, max: f32) -> f32 {
    if v.is_nan() { 0.0 } else { v.clamp(-max, max) }
}

/// The fraction of the way to its command a wheel with first-order lag `tau` covers in `dt`:
/// `1 - exp(-dt / tau)`, or 1 (the command at once) for `tau <= 0`.
pub fn lag_fraction(tau: f32, dt: f32) -> f32 {
    if tau > 0.0 {
        -(-dt.max(0.0) / tau).exp_m1()
    } else {
        1.0
    }
}

impl DriveState {
    /// Moves the wheel speeds toward the clamped command over `dt` (exact first-order response).
    ///
    /// `v += (cmd - v) * (1 - exp(-dt / tau))` with `tau = params.motor_lag`; `tau <= 0` follows the
    /// command at once. Commands are clamped to `+-max_wheel_speed`, NaN counts as 0.
    pub fn update(&mut self, cmd: WheelCommand, params: &ColiasParams, dt: f32) {
        self.approach(cmd, params, [1.0, 1.0], lag_fraction(params.motor_lag, dt));
    }

    /// [`Self::update`] for a robot of its own (`[individual]`): time constant `tau` instead of
    /// `params.motor_lag`, and each clamped command component times its wheel's `scale` (a wheel
    /// that runs slow at the same command). With `tau = params.motor_lag` and scales of 1 the
    /// results are bit for bit [`Self::update`]'s (`x * 1.0 == x`).
    pub fn update_with(
        &mut self,
        cmd: WheelCommand,
        params: &ColiasParams,
        tau: f32,
        scale: [f32; 2],
        dt: f32,
    ) {
        self.approach(cmd, params, scale, lag_fraction(tau, dt));
    }

    /// [`Self::update_with`] with its [`lag_fraction`] given: a world whose robots share one lag
    /// computes the exponential once a step, not once a robot.
    pub fn approach(
        &mut self,
        cmd: WheelCommand,
        params: &ColiasParams,
        scale: [f32; 2],
        alpha: f32,
    ) {
        let max = params.max_wheel_speed.abs();
        let l = clamp_command(cmd.left, max) * scale[0];
        let r = clamp_command(cmd.right, max) * scale[1];
        self.left += (l - self.left) * alpha;
        self.right += (r - self.right) * alpha;
    }
    /// Body velocities: (forward speed m/s, yaw rate rad/s).
    pub fn body_velocity(&self, params: &ColiasParams) -> (f32, f32) {
        let forward = 0.5 * (self.left + self.right);
        let yaw = if params.wheel_base > 0.0 {
            (self.right - self.left) / params.wheel_base
        } else {
            0.0
        };
        (forward, yaw)
    }
}
