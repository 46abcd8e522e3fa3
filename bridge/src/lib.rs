//! The wire-protocol layer of the ColCOSPhi hardware bridge: the SwarmCon / CosPhi tracker stream,
//! JSON pose datagrams, the Colias serial protocol, and the transports that carry them, chosen by URL.
//!
//! The live loop calls [`open_pose_source`] and [`open_robot_link`] and then, every tick,
//! [`PoseSource::poll`], [`RobotLink::send`] and [`RobotLink::pump`].

pub mod colias;
pub mod link;
pub mod source;
pub mod swarmcon;
pub mod udp_pose;
pub mod url;

pub use link::{LinkCounters, LinkError, RobotLink, open_robot_link};
pub use source::{
    ConnectionState, PoseSnapshot, PoseSource, SourceCounters, SourceError, SourceOptions,
    TrackedPose, open_pose_source,
};
