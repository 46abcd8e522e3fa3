//! The twin's robots as firmware with an on-board policy: each keeps its own runtime parameter
//! block, takes `PWP` and `PRN`, runs the policy on its own readings every control tick while it is
//! on, and goes back to the host's commands on any motion command or when its link falls silent.
use super::{OnboardFirmware, RawReadings};
use crate::protocol::colias::{HostCommand, OnboardStatus, PolicyMode};
use colcos_sim::behaviour::WheelCommand;

struct Robot {
    params: Vec<f32>,
    mode: PolicyMode,
    last: (f32, f32),
    accepted: u8,
    refused: u8,
}

pub struct OnboardFleet {
    firmware: OnboardFirmware,
    robots: Vec<Robot>,
}

impl OnboardFleet {
    /// `n` robots flashed with `firmware`, each with its default parameters, obeying the host.
    pub fn new(firmware: OnboardFirmware, n: usize) -> OnboardFleet {
        let robots = (0..n)
            .map(|_| Robot {
                params: firmware.default_params(),
                mode: PolicyMode::Host,
                last: (0.0, 0.0),
                accepted: 0,
                refused: 0,
            })
            .collect();
        OnboardFleet { firmware, robots }
    }

    /// Robot `i` heard `cmd`: `PWP` and `PRN` are taken here; a motion or wheel-speed command takes
    /// it back to the host's commands (the caller applies it).
    pub fn hear(&mut self, i: usize, cmd: &HostCommand) {
        let Some(r) = self.robots.get_mut(i) else {
            return;
        };
        match *cmd {
            HostCommand::WriteParamsAt {
                offset,
                count,
                values,
            } => {
                if self
                    .firmware
                    .write_params(&mut r.params, offset, count, &values)
                {
                    r.accepted = r.accepted.wrapping_add(1);
                } else {
                    r.refused = r.refused.wrapping_add(1);
                }
            }
            HostCommand::RunPolicy { hash } => {
                if hash == self.firmware.hash() {
                    if r.mode != PolicyMode::Running {
                        r.last = (0.0, 0.0);
                    }
                    r.mode = PolicyMode::Running;
                } else {
                    r.mode = PolicyMode::Refused;
                }
            }
            HostCommand::Motion { .. } | HostCommand::WheelSpeeds { .. } => {
                r.mode = PolicyMode::Host;
            }
            HostCommand::WriteParams(_) | HostCommand::RequestTelemetry(_) => {}
        }
    }

    /// Whether robot `i` runs its policy.
    pub fn running(&self, i: usize) -> bool {
        self.robots
            .get(i)
            .is_some_and(|r| r.mode == PolicyMode::Running)
    }

    /// Robot `i`'s link fell silent: it stops and waits for the host.
    pub fn lose_link(&mut self, i: usize) {
        if let Some(r) = self.robots.get_mut(i)
            && r.mode == PolicyMode::Running
        {
            r.mode = PolicyMode::Host;
            r.last = (0.0, 0.0);
        }
    }

    /// One control tick of robot `i`'s policy on its raw readings: the wheel command it drives with.
    pub fn control(&mut self, i: usize, raw: &RawReadings) -> WheelCommand {
        let Some(r) = self.robots.get_mut(i) else {
            return WheelCommand::STOP;
        };
        r.last = self.firmware.step(&r.params, raw, r.last);
        WheelCommand {
            left: r.last.0,
            right: r.last.1,
        }
    }

    /// Robot `i`'s parameter block.
    pub fn params(&self, i: usize) -> &[f32] {
        self.robots
            .get(i)
            .map(|r| r.params.as_slice())
            .unwrap_or(&[])
    }

    /// What robot `i`'s telemetry says of its policy; `driving` is the command it drives with.
    pub fn status(&self, i: usize, driving: WheelCommand) -> OnboardStatus {
        let Some(r) = self.robots.get(i) else {
            return OnboardStatus::default();
        };
        OnboardStatus {
            mode: r.mode,
            hash: self.firmware.hash(),
            writes_accepted: r.accepted,
            writes_refused: r.refused,
            left: driving.left,
            right: driving.right,
        }
    }
}
