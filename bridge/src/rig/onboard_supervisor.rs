//! The live loop's side of an on-board policy (`[rig] onboard`): per robot, upload its runtime
//! parameters, start the policy and keep it running with `PRN` at the keep-alive rate, and hold it
//! with a stop while the watchdog, the tracker, its radio or the shield say so. The wheel speeds a
//! robot chose come back in its telemetry; they stand for the command in the host's dead reckoning,
//! the shield's look-ahead and the log.
use super::stopper::stop_packet;
use crate::onboard::{OnboardManifest, robot_params, upload_packets};
use crate::protocol::colias::{CommandPacket, HostCommand, PolicyMode, Telemetry};
use colcos_sim::behaviour::WheelCommand;
use colcos_sim::scenario::{Firmware, Scenario};
use colcos_sim::sensors::ColourCalibration;

struct Robot {
    radio: u8,
    params: Vec<f32>,
    uploaded: bool,
    /// A `PRN` was sent and no stop since.
    started: bool,
    /// When the last `PRN` or stop went out, s.
    last_frame: f64,
    /// The wheel speeds its policy last chose while running (stop until it has run).
    chosen: WheelCommand,
    /// It runs another policy, or none: held stopped, said once.
    refused: bool,
}

pub(crate) struct OnboardSupervisor {
    hash: u32,
    robots: Vec<Robot>,
}

impl OnboardSupervisor {
    /// The host's side for `manifest` and the robots at `radio` addresses: each robot's parameters
    /// from the rig's wheel-speed limit and its colour calibration.
    pub(crate) fn new(
        manifest: &OnboardManifest,
        scenario: &Scenario,
        calibration: Option<&ColourCalibration>,
        radio: &[u8],
    ) -> OnboardSupervisor {
        let limit = scenario
            .spec
            .robot
            .max_wheel_speed
            .min(scenario.spec.rig.shield.max_wheel_speed);
        let robots = radio
            .iter()
            .map(|&r| Robot {
                radio: r,
                params: robot_params(manifest, limit, calibration, r),
                uploaded: false,
                started: false,
                last_frame: f64::NEG_INFINITY,
                chosen: WheelCommand::STOP,
                refused: false,
            })
            .collect();
        OnboardSupervisor {
            hash: manifest.hash,
            robots,
        }
    }

    /// Takes robot `i`'s telemetry; an event (JSON) when it turns out to run another policy or none.
    pub(crate) fn take_telemetry(&mut self, i: usize, tm: &Telemetry) -> Option<String> {
        let hash = self.hash;
        let r = self.robots.get_mut(i)?;
        let status = tm.onboard();
        if status.mode == PolicyMode::Running {
            r.chosen = WheelCommand {
                left: status.left,
                right: status.right,
            };
        }
        let wrong = match status.mode {
            PolicyMode::None => Some("its firmware reports no on-board policy".to_string()),
            PolicyMode::Refused => Some(format!(
                "it refused policy {hash:#010x}: it carries {:#010x}",
                status.hash
            )),
            _ if status.hash != hash => Some(format!(
                "it carries policy {:#010x}, not {hash:#010x}",
                status.hash
            )),
            _ => None,
        };
        let why = wrong.filter(|_| !r.refused)?;
        r.refused = true;
        log::warn!("robot {i} (radio {}): {why}; held stopped", r.radio);
        let detail = format!("radio {}: {why}", r.radio);
        Some(
            serde_json::json!({"kind": "onboard_policy_refused", "robot": i, "detail": detail})
                .to_string(),
        )
    }

    /// What robot `i`'s policy last chose (a stop before it has run): the command the shield looks
    /// ahead with, also while the robot is held. The host cannot ask the policy what it would do
    /// now, so a robot the shield stopped stays stopped while that choice would still cross a wall.
    pub(crate) fn intent(&self, i: usize) -> WheelCommand {
        match self.robots.get(i) {
            Some(r) if !r.refused => r.chosen,
            _ => WheelCommand::STOP,
        }
    }

    /// Robot `i`'s frames this tick at `t` s (`stamp` ms): a stop when `hold` (or it was refused),
    /// else its parameters once and `PRN` at start and every `keepalive` s. Whether it may drive.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn frames(
        &mut self,
        i: usize,
        t: f64,
        stamp: u32,
        hold: bool,
        keepalive: f64,
        firmware: Firmware,
        out: &mut Vec<CommandPacket>,
    ) -> bool {
        let hash = self.hash;
        let Some(r) = self.robots.get_mut(i) else {
            return false;
        };
        if hold || r.refused {
            // A stop overrides the policy; repeated at the keep-alive rate like any command.
            if r.started || t - r.last_frame >= keepalive {
                out.push(stop_packet(r.radio, stamp, firmware));
                r.started = false;
                r.last_frame = t;
            }
            return false;
        }
        if !r.uploaded {
            out.extend(upload_packets(r.radio, stamp, &r.params));
            r.uploaded = true;
        }
        if !r.started || t - r.last_frame >= keepalive {
            out.push(CommandPacket::new(
                r.radio,
                stamp,
                HostCommand::RunPolicy { hash },
            ));
            r.started = true;
            r.last_frame = t;
        }
        true
    }
}
