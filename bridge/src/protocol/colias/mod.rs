//! The ColCOSPhi host <-> Colias serial protocol: `0x01 0xFE | payload | 0xFE 0x01` frames with a
//! fixed payload length per direction (32 bytes host to robot, 96 bytes robot to host), no length
//! field and no checksum.

mod command;
mod frame;
mod legacy;
mod onboard_status;
mod telemetry;

pub use command::{CommandError, CommandPacket, HostCommand, MotionKind};
use frame::encode_frame;
pub use frame::{DecoderCounters, FrameDecoder};
pub(crate) use legacy::TELEMETRY_TO_SIM;
pub use legacy::{LegacyDrive, colour_from_sim, colour_to_sim};
pub use onboard_status::{OnboardStatus, PolicyMode};
pub use telemetry::Telemetry;

/// Frame start marker.
pub(crate) const HEADER: [u8; 2] = [0x01, 0xFE];
/// Frame end marker.
pub(crate) const TRAILER: [u8; 2] = [0xFE, 0x01];
/// Host-to-robot payload length.
pub const COMMAND_LEN: usize = 32;
/// Robot-to-host payload length (Python struct `'=1B1L2B3h6H2H12H9f7B'`).
pub const TELEMETRY_LEN: usize = 96;
/// A whole command frame on the wire.
pub(crate) const COMMAND_FRAME_LEN: usize = COMMAND_LEN + 4;
/// A whole telemetry frame on the wire.
pub(crate) const TELEMETRY_FRAME_LEN: usize = TELEMETRY_LEN + 4;
/// The robot id that addresses every robot.
pub const BROADCAST_ID: u8 = 200;
/// The serial line's default speed.
pub(crate) const DEFAULT_BAUD: u32 = 115_200;

/// Seconds a frame of `frame_len` bytes occupies the line at `baud`, 8N1 (10 bits a byte).
pub(crate) fn airtime_s(frame_len: usize, baud: u32) -> f64 {
    (frame_len * 10) as f64 / baud.max(1) as f64
}

/// Decodes host-to-robot frames (the robot's or the twin's side).
pub type CommandDecoder = FrameDecoder<COMMAND_LEN>;
/// Decodes robot-to-host frames (the host's side).
pub type TelemetryDecoder = FrameDecoder<TELEMETRY_LEN>;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn airtime_matches_the_published_figures() {
        assert!((airtime_s(COMMAND_FRAME_LEN, DEFAULT_BAUD) * 1e3 - 3.125).abs() < 1e-9);
        assert!((airtime_s(TELEMETRY_FRAME_LEN, DEFAULT_BAUD) * 1e3 - 8.68).abs() < 0.01);
    }
}
