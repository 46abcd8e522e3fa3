//! Pose sources behind one non-blocking trait: a background thread per source receives, parses and
//! converts poses to the simulator's frame; the live loop polls for the newest snapshot.

mod replay;
mod shared;
mod swarmcon_client;
mod udp;

use replay::load_replay;
use shared::ThreadedSource;

use crate::protocol::swarmcon::{Calibrate, FrameTransform, SlotState, TrackerEvent, TrackerFrame};
use crate::transport::{PoseUrl, UrlError};
use colcos_sim::robot::Pose;
use std::time::{Duration, Instant};
use thiserror::Error;

/// One robot's tracked pose, in the simulator's frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MarkerPose {
    pub id: u32,
    pub pose: Pose,
    /// Detected in the newest camera frame (false: last known pose).
    pub fresh: bool,
    /// Source time of the detection, s.
    pub t: f64,
}

/// Every robot's newest pose at one moment.
#[derive(Clone, Debug, PartialEq)]
pub struct PoseSnapshot {
    /// Increases by one with each snapshot the source publishes.
    pub seq: u64,
    /// Source time of the frame, s (epoch seconds for SwarmCon).
    pub t: f64,
    /// When this machine received it.
    pub received: Instant,
    pub poses: Vec<MarkerPose>,
}

/// Whether a source is delivering.
#[derive(Clone, Debug, PartialEq)]
pub enum ConnectionState {
    Connecting,
    Connected,
    /// Lost or never reached; the next attempt is after the backoff. `reason` names the address
    /// and what went wrong ("127.0.0.1:6699: Connection refused (os error 111)").
    Disconnected {
        retry_in: Duration,
        reason: String,
    },
    /// A replay reached its end.
    Finished,
    /// Cannot go on (a bad file, an address that cannot be bound).
    Failed(String),
}

/// Running totals of a source.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SourceCounters {
    pub bytes: u64,
    /// Snapshots published.
    pub frames: u64,
    /// Lines, datagrams or blocks that could not be used.
    pub errors: u64,
    /// Successful connections after the first.
    pub reconnects: u64,
}

#[derive(Debug, Error)]
pub enum SourceError {
    #[error(transparent)]
    Url(#[from] UrlError),
    #[error("{0}")]
    Io(#[from] std::io::Error),
    #[error("replay file {path}: {reason}")]
    Replay { path: String, reason: String },
    #[error("this pose source cannot calibrate")]
    NoCalibration,
    #[error(transparent)]
    Calibrate(#[from] crate::protocol::swarmcon::CalibrateError),
}

/// A tracker as the live loop sees it. Every method returns at once.
pub trait PoseSource: Send {
    /// The newest snapshot if one arrived since the last call; older ones are skipped.
    fn poll(&mut self) -> Option<PoseSnapshot>;
    /// The newest snapshot, whether or not it was polled.
    fn latest(&self) -> Option<PoseSnapshot>;
    fn state(&self) -> ConnectionState;
    fn counters(&self) -> SourceCounters;
    /// Why no pose is arriving, naming the address ("127.0.0.1:6699: Connection refused"); None
    /// while frames arrive (and before the first attempt has failed).
    fn problem(&self) -> Option<String> {
        None
    }
    /// Events (`Calibrated`, `Closed`) since the last call.
    fn take_events(&mut self) -> Vec<TrackerEvent>;
    /// Asks the tracker to calibrate; only SwarmCon can.
    fn request_calibration(&mut self, _cmd: &Calibrate) -> Result<(), SourceError> {
        Err(SourceError::NoCalibration)
    }
}

/// How a source converts and reconnects.
#[derive(Clone, Copy, Debug)]
pub struct SourceOptions {
    pub transform: FrameTransform,
    pub connect_timeout: Duration,
    pub backoff_initial: Duration,
    pub backoff_max: Duration,
}

impl SourceOptions {
    pub fn new(transform: FrameTransform) -> Self {
        SourceOptions {
            transform,
            connect_timeout: Duration::from_secs(1),
            backoff_initial: Duration::from_millis(100),
            backoff_max: Duration::from_secs(5),
        }
    }
}

/// Opens the source a URL names.
pub fn open_pose_source(
    url: &str,
    opts: &SourceOptions,
) -> Result<Box<dyn PoseSource>, SourceError> {
    let src: ThreadedSource = match url.parse::<PoseUrl>()? {
        PoseUrl::SwarmCon { host, port } => swarmcon_client::spawn(format!("{host}:{port}"), *opts),
        PoseUrl::Udp { host, port } => udp::spawn(&format!("{host}:{port}"))?,
        PoseUrl::Replay { path, speed } => {
            let frames = load_replay(&path)?;
            replay::spawn(frames, speed, opts.transform)
        }
    };
    Ok(Box::new(src))
}

/// The identified, ever-seen slots of a frame, in the simulator's frame.
pub fn frame_to_poses(frame: &TrackerFrame, transform: &FrameTransform) -> Vec<MarkerPose> {
    frame
        .robots
        .iter()
        .filter(|s| s.id >= 0 && s.state != SlotState::NeverSeen)
        .map(|s| MarkerPose {
            id: s.id as u32,
            pose: transform.to_sim(s),
            fresh: s.state == SlotState::Fresh,
            t: s.last_seen_us as f64 * 1e-6,
        })
        .collect()
}
