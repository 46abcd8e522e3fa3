//! One robot's own actuation (`[individual]`): its wheels' speed scales, its motor lag and the whole
//! steps its commands wait before reaching the wheels. A robot without an entry has none and drives
//! through the nominal model alone, so scenarios without `[individual]` step exactly as before.
use super::{ColiasParams, DriveState};
use crate::behaviour::WheelCommand;
use std::collections::VecDeque;

#[derive(Clone, Debug, PartialEq)]
pub struct Actuation {
    /// Left, right wheel speed per unit of (clamped) command.
    pub wheel_scale: [f32; 2],
    /// First-order motor time constant, s.
    pub motor_lag: f32,
    /// Commands in flight, oldest first: exactly `delay` of them (the wheels take the front one).
    in_flight: VecDeque<WheelCommand>,
}

impl Actuation {
    /// An actuation whose commands wait `round(latency / dt)` whole steps (half a step rounds up):
    /// a step's command can only reach the wheels at the start of some step, so a latency between
    /// steps acts as the nearest whole number of them.
    pub fn new(wheel_scale: [f32; 2], motor_lag: f32, latency: f32, dt: f32) -> Self {
        let delay = Self::delay_steps(latency, dt);
        Actuation {
            wheel_scale,
            motor_lag,
            in_flight: std::iter::repeat_n(WheelCommand::STOP, delay).collect(),
        }
    }

    /// Whole steps a command waits for `latency` s at step `dt`.
    pub fn delay_steps(latency: f32, dt: f32) -> usize {
        if dt > 0.0 && latency > 0.0 {
            (latency / dt).round() as usize
        } else {
            0
        }
    }

    /// Steps a command waits.
    pub fn delay(&self) -> usize {
        self.in_flight.len()
    }

    /// Issues `cmd` and drives the wheels one step of `dt` with the command that reaches them now.
    pub fn drive(
        &mut self,
        drive: &mut DriveState,
        cmd: WheelCommand,
        params: &ColiasParams,
        dt: f32,
    ) {
        let now = if self.in_flight.is_empty() {
            cmd
        } else {
            self.in_flight.push_back(cmd);
            self.in_flight.pop_front().unwrap_or(WheelCommand::STOP)
        };
        drive.update_with(now, params, self.motor_lag, self.wheel_scale, dt);
    }
}
