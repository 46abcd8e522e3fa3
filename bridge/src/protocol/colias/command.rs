//! Host-to-robot command payloads: `u8 id`, `u32 t_ms` little-endian, then a command, zero padded
//! to 32 bytes.
//!
//! `MWS` (two `f32` wheel speeds, left then right, m/s) is this bridge's extension for policies that
//! run on the host. Firmware that predates it does not know the code and ignores the frame, so a
//! rig must either run firmware with `MWS` or use [`super::LegacyDrive`] to send motion commands.
//!
//! `PWP` (a `u16` offset, a `u8` count and five `f32`) and `PRN` (a `u32` policy hash) are the
//! extensions for a policy that runs on board (`colcos.onboard.export_c`): the first writes into the
//! policy's runtime parameter block, the second starts the policy the robot was flashed with if its
//! hash matches. Any motion or wheel-speed command takes the robot back to the host's commands.

use super::COMMAND_LEN;
use thiserror::Error;

/// The old firmware's motion commands, each sent with one `f32` speed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum MotionKind {
    /// `MFD`
    Forward,
    /// `MBK`
    Backward,
    /// `MML`
    TurnLeft,
    /// `MMR`
    TurnRight,
    /// `MST`
    Start,
    /// `MSP`
    Stop,
}

impl MotionKind {
    pub const ALL: [MotionKind; 6] = [
        MotionKind::Forward,
        MotionKind::Backward,
        MotionKind::TurnLeft,
        MotionKind::TurnRight,
        MotionKind::Start,
        MotionKind::Stop,
    ];

    pub fn code(self) -> &'static [u8; 3] {
        match self {
            MotionKind::Forward => b"MFD",
            MotionKind::Backward => b"MBK",
            MotionKind::TurnLeft => b"MML",
            MotionKind::TurnRight => b"MMR",
            MotionKind::Start => b"MST",
            MotionKind::Stop => b"MSP",
        }
    }
}

/// One command.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum HostCommand {
    Motion {
        kind: MotionKind,
        speed: f32,
    },
    /// `DWP`: behaviour parameters for the on-board controller; unused slots are zero on the wire.
    WriteParams([f32; 5]),
    /// `DR`: ask for `n` telemetry packets.
    RequestTelemetry(u8),
    /// `MWS`: wheel speeds in m/s (extension; see the module docs).
    WheelSpeeds {
        left: f32,
        right: f32,
    },
    /// `PWP`: `count` (1..=5) of `values` into the on-board policy's parameters from `offset`.
    WriteParamsAt {
        offset: u16,
        count: u8,
        values: [f32; 5],
    },
    /// `PRN`: run the on-board policy whose hash is `hash`.
    RunPolicy {
        hash: u32,
    },
}

/// A whole host-to-robot payload.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CommandPacket {
    /// Robot id, or [`super::BROADCAST_ID`].
    pub id: u8,
    /// Milliseconds since the host started (4 bytes on the wire, wrapping).
    pub t_ms: u32,
    pub command: HostCommand,
}

#[derive(Clone, Debug, Error, PartialEq)]
pub enum CommandError {
    #[error("unknown command code {0:?}")]
    UnknownCode([u8; 3]),
    #[error("`DWP` takes at most 5 parameters, got {0}")]
    TooManyParams(usize),
}

fn f32_at(p: &[u8; COMMAND_LEN], at: usize) -> f32 {
    f32::from_le_bytes([p[at], p[at + 1], p[at + 2], p[at + 3]])
}

fn put_f32(p: &mut [u8; COMMAND_LEN], at: usize, v: f32) {
    p[at..at + 4].copy_from_slice(&v.to_le_bytes());
}

impl HostCommand {
    /// `DWP` from up to five parameters.
    pub fn write_params(params: &[f32]) -> Result<HostCommand, CommandError> {
        if params.len() > 5 {
            return Err(CommandError::TooManyParams(params.len()));
        }
        let mut a = [0.0; 5];
        a[..params.len()].copy_from_slice(params);
        Ok(HostCommand::WriteParams(a))
    }
}

impl CommandPacket {
    pub fn new(id: u8, t_ms: u32, command: HostCommand) -> Self {
        CommandPacket { id, t_ms, command }
    }

    /// The 32-byte payload.
    pub fn encode(&self) -> [u8; COMMAND_LEN] {
        let mut p = [0u8; COMMAND_LEN];
        p[0] = self.id;
        p[1..5].copy_from_slice(&self.t_ms.to_le_bytes());
        match self.command {
            HostCommand::Motion { kind, speed } => {
                p[5..8].copy_from_slice(kind.code());
                put_f32(&mut p, 8, speed);
            }
            HostCommand::WriteParams(a) => {
                p[5..8].copy_from_slice(b"DWP");
                for (k, v) in a.iter().enumerate() {
                    put_f32(&mut p, 8 + 4 * k, *v);
                }
            }
            HostCommand::RequestTelemetry(n) => {
                p[5..7].copy_from_slice(b"DR");
                p[7] = n;
            }
            HostCommand::WheelSpeeds { left, right } => {
                p[5..8].copy_from_slice(b"MWS");
                put_f32(&mut p, 8, left);
                put_f32(&mut p, 12, right);
            }
            HostCommand::WriteParamsAt {
                offset,
                count,
                values,
            } => {
                p[5..8].copy_from_slice(b"PWP");
                p[8..10].copy_from_slice(&offset.to_le_bytes());
                p[10] = count;
                for (k, v) in values.iter().enumerate() {
                    put_f32(&mut p, 11 + 4 * k, *v);
                }
            }
            HostCommand::RunPolicy { hash } => {
                p[5..8].copy_from_slice(b"PRN");
                p[8..12].copy_from_slice(&hash.to_le_bytes());
            }
        }
        p
    }

    /// Reads a 32-byte payload; padding is not checked.
    pub fn decode(p: &[u8; COMMAND_LEN]) -> Result<CommandPacket, CommandError> {
        let id = p[0];
        let t_ms = u32::from_le_bytes([p[1], p[2], p[3], p[4]]);
        let code = [p[5], p[6], p[7]];
        let command = if let Some(kind) = MotionKind::ALL.iter().find(|k| *k.code() == code) {
            HostCommand::Motion {
                kind: *kind,
                speed: f32_at(p, 8),
            }
        } else if &code == b"DWP" {
            HostCommand::WriteParams(std::array::from_fn(|k| f32_at(p, 8 + 4 * k)))
        } else if &code == b"MWS" {
            HostCommand::WheelSpeeds {
                left: f32_at(p, 8),
                right: f32_at(p, 12),
            }
        } else if &code == b"PWP" {
            HostCommand::WriteParamsAt {
                offset: u16::from_le_bytes([p[8], p[9]]),
                count: p[10],
                values: std::array::from_fn(|k| f32_at(p, 11 + 4 * k)),
            }
        } else if &code == b"PRN" {
            HostCommand::RunPolicy {
                hash: u32::from_le_bytes([p[8], p[9], p[10], p[11]]),
            }
        } else if &code[..2] == b"DR" {
            HostCommand::RequestTelemetry(code[2])
        } else {
            return Err(CommandError::UnknownCode(code));
        };
        Ok(CommandPacket { id, t_ms, command })
    }

    /// The whole frame, header and trailer included.
    pub fn to_frame(&self) -> Vec<u8> {
        super::encode_frame(&self.encode())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn layout_is_byte_exact() {
        let p = CommandPacket::new(
            7,
            0x0403_0201,
            HostCommand::Motion {
                kind: MotionKind::Forward,
                speed: 1.0,
            },
        )
        .encode();
        assert_eq!(
            &p[..12],
            &[7, 1, 2, 3, 4, b'M', b'F', b'D', 0, 0, 0x80, 0x3F]
        );
        assert!(p[12..].iter().all(|&b| b == 0));
        let d = CommandPacket::new(200, 5, HostCommand::RequestTelemetry(3)).encode();
        assert_eq!(&d[..9], &[200, 5, 0, 0, 0, b'D', b'R', 3, 0]);
        let w = CommandPacket::new(
            2,
            1,
            HostCommand::WriteParamsAt {
                offset: 0x0102,
                count: 2,
                values: [1.0, -2.0, 0.0, 0.0, 0.0],
            },
        )
        .encode();
        assert_eq!(
            &w[..19],
            &[
                2, 1, 0, 0, 0, b'P', b'W', b'P', 0x02, 0x01, 2, 0, 0, 0x80, 0x3F, 0, 0, 0, 0xC0
            ]
        );
        assert!(w[19..].iter().all(|&b| b == 0));
        let r = CommandPacket::new(4, 0, HostCommand::RunPolicy { hash: 0xDEAD_BEEF }).encode();
        assert_eq!(
            &r[..12],
            &[4, 0, 0, 0, 0, b'P', b'R', b'N', 0xEF, 0xBE, 0xAD, 0xDE]
        );
    }

    #[test]
    fn every_command_round_trips() {
        let cmds = [
            HostCommand::Motion {
                kind: MotionKind::TurnRight,
                speed: 0.2,
            },
            HostCommand::write_params(&[1.0, -2.0, 3.5]).unwrap(),
            HostCommand::RequestTelemetry(255),
            HostCommand::WheelSpeeds {
                left: -0.1,
                right: 0.3,
            },
            HostCommand::WriteParamsAt {
                offset: 58,
                count: 5,
                values: [1.0, 2.0, 3.0, 4.0, 5.5],
            },
            HostCommand::RunPolicy { hash: 7 },
        ];
        for c in cmds {
            let p = CommandPacket::new(3, 99, c);
            assert_eq!(CommandPacket::decode(&p.encode()).unwrap(), p);
        }
        assert!(HostCommand::write_params(&[0.0; 6]).is_err());
        assert!(CommandPacket::decode(&[0u8; 32]).is_err());
    }
}
