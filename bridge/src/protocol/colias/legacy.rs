//! Bridges between the simulator's conventions and what the robots speak: wheel speeds onto the old
//! firmware's motion commands, and the telemetry's colour-sensor order onto the simulator's.

use super::{HostCommand, MotionKind};
use colcos_sim::behaviour::WheelCommand;

/// For each telemetry colour sensor (front, back, left, right), its simulator index
/// (n = 0 right / Y-, 1 front / X+, 2 left / Y+, 3 back / X-).
pub(crate) const TELEMETRY_TO_SIM: [usize; 4] = [1, 3, 2, 0];

/// Telemetry colour counts (front, back, left, right) in the simulator's sensor order.
pub fn colour_to_sim(wire: [[u16; 3]; 4]) -> [[u16; 3]; 4] {
    let mut sim = [[0; 3]; 4];
    for (w, s) in TELEMETRY_TO_SIM.iter().enumerate() {
        sim[*s] = wire[w];
    }
    sim
}

/// Simulator-order colour counts in the telemetry's order (for the twin).
pub fn colour_from_sim(sim: [[u16; 3]; 4]) -> [[u16; 3]; 4] {
    std::array::from_fn(|w| sim[TELEMETRY_TO_SIM[w]])
}

/// Maps wheel speeds onto the old firmware's forward / backward / turn / stop commands, for robots
/// without `MWS`. A differential command is split into its mean (drive) and half-difference (turn)
/// and the larger part wins, so the robot does one thing at a time, as that firmware can.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LegacyDrive {
    /// Both wheels slower than this (m/s) means stop.
    pub deadband: f32,
    /// Multiplies m/s into the firmware's speed argument. Its unit is not published; calibrate it on
    /// the rig (1.0 sends m/s unchanged).
    pub speed_scale: f32,
}

impl Default for LegacyDrive {
    fn default() -> Self {
        LegacyDrive {
            deadband: 0.005,
            speed_scale: 1.0,
        }
    }
}

impl LegacyDrive {
    pub fn map(&self, cmd: WheelCommand) -> HostCommand {
        let (l, r) = (finite(cmd.left), finite(cmd.right));
        let drive = (l + r) / 2.0;
        let turn = (r - l) / 2.0;
        let (kind, speed) = if l.abs().max(r.abs()) < self.deadband {
            (MotionKind::Stop, 0.0)
        } else if drive.abs() >= turn.abs() {
            if drive >= 0.0 {
                (MotionKind::Forward, drive)
            } else {
                (MotionKind::Backward, -drive)
            }
        } else if turn > 0.0 {
            (MotionKind::TurnLeft, turn)
        } else {
            (MotionKind::TurnRight, -turn)
        };
        HostCommand::Motion {
            kind,
            speed: speed * self.speed_scale,
        }
    }
}

/// NaN or infinite speeds from a misbehaving policy become a stop, never a full-speed command.
fn finite(v: f32) -> f32 {
    if v.is_finite() { v } else { 0.0 }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn kind(l: f32, r: f32) -> (MotionKind, f32) {
        match LegacyDrive::default().map(WheelCommand::new(l, r)) {
            HostCommand::Motion { kind, speed } => (kind, speed),
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn wheel_speeds_to_motion() {
        assert_eq!(kind(0.2, 0.2), (MotionKind::Forward, 0.2));
        assert_eq!(kind(-0.1, -0.1), (MotionKind::Backward, 0.1));
        assert_eq!(kind(-0.1, 0.1), (MotionKind::TurnLeft, 0.1));
        assert_eq!(kind(0.1, -0.1), (MotionKind::TurnRight, 0.1));
        assert_eq!(kind(0.001, -0.002), (MotionKind::Stop, 0.0));
        assert_eq!(kind(f32::NAN, f32::INFINITY), (MotionKind::Stop, 0.0));
    }

    #[test]
    fn sensor_order() {
        let wire = [[1; 3], [2; 3], [3; 3], [4; 3]]; // front, back, left, right
        let sim = colour_to_sim(wire);
        assert_eq!(sim, [[4; 3], [1; 3], [3; 3], [2; 3]]); // right, front, left, back
        assert_eq!(colour_from_sim(sim), wire);
    }
}
