//! What a robot running a colcos on-board policy reports about it, in the telemetry fields the
//! original firmware leaves to its controller: `reserved[0]` the mode, `reserved[1..5]` the hash of
//! the policy it was flashed with (`u32` little-endian), `reserved[5]` / `reserved[6]` its accepted /
//! refused parameter writes (wrapping counters), `controller[7]` / `controller[8]` the wheel speeds it
//! chose last (left, right, m/s). Firmware without the policy leaves them zero: mode `None`.
use super::Telemetry;

/// The robot's control mode.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum PolicyMode {
    /// Not reported: firmware without an on-board policy.
    #[default]
    None,
    /// Obeying the host's motion and wheel-speed commands.
    Host,
    /// Running its on-board policy.
    Running,
    /// Asked to run a policy whose hash is not the one it was flashed with: stopped.
    Refused,
}

impl PolicyMode {
    fn byte(self) -> u8 {
        match self {
            PolicyMode::None => 0,
            PolicyMode::Host => 1,
            PolicyMode::Running => 2,
            PolicyMode::Refused => 3,
        }
    }
    fn from_byte(b: u8) -> PolicyMode {
        match b {
            1 => PolicyMode::Host,
            2 => PolicyMode::Running,
            3 => PolicyMode::Refused,
            _ => PolicyMode::None,
        }
    }
}

/// The on-board policy's state as telemetry carries it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct OnboardStatus {
    pub mode: PolicyMode,
    /// Hash of the policy in the robot's flash.
    pub hash: u32,
    /// Parameter writes (`PWP`) accepted and refused, wrapping at 256.
    pub writes_accepted: u8,
    pub writes_refused: u8,
    /// The wheel speeds the robot chose last, m/s.
    pub left: f32,
    pub right: f32,
}

impl Telemetry {
    /// The on-board policy's state this packet reports.
    pub fn onboard(&self) -> OnboardStatus {
        let r = &self.reserved;
        OnboardStatus {
            mode: PolicyMode::from_byte(r[0]),
            hash: u32::from_le_bytes([r[1], r[2], r[3], r[4]]),
            writes_accepted: r[5],
            writes_refused: r[6],
            left: self.controller[7],
            right: self.controller[8],
        }
    }

    /// Writes `status` into its fields (the twin's robots).
    pub fn set_onboard(&mut self, status: &OnboardStatus) {
        self.reserved[0] = status.mode.byte();
        self.reserved[1..5].copy_from_slice(&status.hash.to_le_bytes());
        self.reserved[5] = status.writes_accepted;
        self.reserved[6] = status.writes_refused;
        self.controller[7] = status.left;
        self.controller[8] = status.right;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::protocol::colias::TELEMETRY_LEN;

    #[test]
    fn status_sits_in_the_reserved_bytes_and_last_controller_floats() {
        let mut t = Telemetry::default();
        assert_eq!(t.onboard().mode, PolicyMode::None);
        let s = OnboardStatus {
            mode: PolicyMode::Running,
            hash: 0x0403_0201,
            writes_accepted: 12,
            writes_refused: 1,
            left: 0.25,
            right: -0.5,
        };
        t.set_onboard(&s);
        let p = t.encode();
        assert_eq!(&p[TELEMETRY_LEN - 7..], &[2, 1, 2, 3, 4, 12, 1]);
        // controller[7], controller[8]: the last two f32 before the reserved bytes.
        assert_eq!(
            &p[TELEMETRY_LEN - 15..TELEMETRY_LEN - 11],
            &0.25f32.to_le_bytes()
        );
        assert_eq!(
            &p[TELEMETRY_LEN - 11..TELEMETRY_LEN - 7],
            &(-0.5f32).to_le_bytes()
        );
        assert_eq!(Telemetry::decode(&p).onboard(), s);
    }
}
