//! Transports: what carries the wire formats between this machine and the rig. Pose sources
//! ([`PoseSource`]: a SwarmCon TCP client, JSON pose datagrams, a replayed log) and robot links
//! ([`RobotLink`]: a serial port or UDP behind an airtime scheduler) are opened from URLs
//! (`swarmcon://`, `udp://`, `replay://`, `serial://`); the frame stream ([`FrameServer`]) carries
//! the displayed screen to the twin; [`ClockOffset`] relates a source's clock to this machine's.
mod clock;
mod frames;
mod link;
mod source;
mod url;

pub use clock::ClockOffset;
pub(crate) use clock::{epoch_ns, epoch_s};
pub(crate) use frames::FrameClient;
pub use frames::FrameServer;
pub use link::{
    AirtimeScheduler, Link, LinkCounters, LinkError, RobotLink, SchedulerCounters, SerialWire,
    Wire, open_robot_link,
};
pub use source::{
    ConnectionState, MarkerPose, PoseSnapshot, PoseSource, SourceCounters, SourceError,
    SourceOptions, frame_to_poses, open_pose_source,
};
pub use url::{PoseUrl, UrlError};
