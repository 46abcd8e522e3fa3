//! The ColCOSPhi hardware bridge: the wire protocols (the SwarmCon / CosPhi tracker stream, JSON pose
//! datagrams, the Colias serial protocol) and the transports that carry them, chosen by URL; the live
//! loop that runs the simulator's own injection, field, screen and sensing stages with the real arena
//! ([`live`], [`host`]); the safety watchdog; the rig log; and the digital twin that plays the rig
//! over the same wire formats ([`twin`]).
//!
//! The live loop calls [`open_pose_source`] and [`open_robot_link`] and then, every tick,
//! [`PoseSource::poll`], [`RobotLink::send`] and [`RobotLink::pump`].

pub mod calibrate;
pub mod clock;
pub mod colias;
pub mod frames;
pub mod host;
pub mod identify;
pub mod link;
pub mod live;
pub mod onboard;
pub mod recorder;
pub mod source;
pub mod swarmcon;
pub mod twin;
pub mod udp_pose;
pub mod url;
pub mod watchdog;

pub use link::{LinkCounters, LinkError, RobotLink, open_robot_link};
pub use source::{
    ConnectionState, PoseSnapshot, PoseSource, SourceCounters, SourceError, SourceOptions,
    TrackedPose, open_pose_source,
};
