//! The SwarmCon / CosPhi position server's TCP stream: frame types, a streaming parser, a writer that
//! formats blocks byte for byte as the C server does, the `Calibrate` command, and the transform from
//! the tracker's image-aligned frame to the simulator's.

mod calibrate;
mod line;
mod parse;
mod stream;
mod transform;
mod write;

pub use calibrate::{Calibrate, CalibrateError};
pub use parse::{TrackerError, TrackerLine, parse_line};
pub use stream::{ParserCounters, StreamParser, TrackerMessage};
pub use transform::FrameTransform;
pub(crate) use write::write_event;
pub use write::{HeaderForm, write_block};

/// The TCP port the position server listens on.
pub(crate) const DEFAULT_PORT: u16 = 6666;
/// Lines longer than this are dropped (a real line is under 60 bytes).
pub(crate) const MAX_LINE: usize = 4096;
/// Most slots one block may announce; the server itself caps it at 100.
pub(crate) const MAX_SLOTS: usize = 1024;

/// Whether a slot's pose comes from this camera frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum SlotState {
    /// Detected in this frame (last-seen time equals the frame time).
    Fresh,
    /// Last known pose; the robot was not detected in this frame.
    Stale,
    /// Never detected since the server started (last-seen time `-1`).
    NeverSeen,
}

/// One `Robot` line: a tracked slot in the tracker's frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SlotPose {
    /// Marker ID; `-1` is an unidentified pattern (used for calibration circles).
    pub id: i32,
    /// Metres from the top-left calibration pattern along the arena length.
    pub x: f64,
    /// Metres from the top-left calibration pattern, pointing down in the image.
    pub y: f64,
    /// Degrees, in image axes (y down).
    pub yaw_deg: f64,
    /// Epoch microseconds of the last detection, `-1` when never seen.
    pub last_seen_us: i64,
    pub state: SlotState,
}

impl SlotPose {
    /// Classifies a slot from its last-seen time against the frame time.
    pub fn state_for(last_seen_us: i64, frame_t_us: i64) -> SlotState {
        if last_seen_us == -1 {
            SlotState::NeverSeen
        } else if last_seen_us == frame_t_us {
            SlotState::Fresh
        } else {
            SlotState::Stale
        }
    }

    /// An identified marker (not a calibration circle).
    pub fn is_identified(&self) -> bool {
        self.id >= 0
    }
}

/// One complete block: the header and every slot it announced.
#[derive(Clone, Debug, PartialEq)]
pub struct TrackerFrame {
    /// Frame time, epoch microseconds.
    pub t_us: i64,
    /// Patterns found in this frame.
    pub found: i32,
    /// Slots tracked (the number of `Robot` lines).
    pub tracked: i32,
    /// Slots updated since the previous block (CosPhi's header form only).
    pub updated: Option<i32>,
    pub robots: Vec<SlotPose>,
}

/// Non-pose lines of the stream.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TrackerEvent {
    /// A calibration requested with `Calibrate` has finished.
    Calibrated,
    /// The server is shutting down.
    Closed,
}
