//! The ColCOSPhi hardware bridge, in layers, each using only those below it:
//!
//! - [`geometry`]: homographies and the calibrated tracker-to-simulator map;
//! - [`protocol`]: the wire formats (the SwarmCon / CosPhi tracker stream, the Colias serial
//!   protocol, JSON pose datagrams), bytes to values and back;
//! - [`transport`]: what carries them, chosen by URL: pose sources, robot links, the frame stream;
//! - [`onboard`]: policies exported to C that run on the robots themselves;
//! - [`calibrate`]: the screen, latency and colour calibrations of a rig;
//! - [`twin`]: the digital twin that plays the rig over the same wire formats;
//! - [`rig`]: the live loop that runs the simulator's own injection, field, screen and sensing stages
//!   with the real arena, its watchdog, the rig log and its replay;
//! - [`identify`]: each robot's parameters fitted from a rig log.
//!
//! A live run opens a tracker with [`open_pose_source`] and the robots with [`open_robot_link`],
//! and hands both to a [`LiveSession`].
// What no other crate uses stays inside: a `pub` item must be reachable from the crate root, and a
// type in a public signature must be nameable there.
#![warn(unreachable_pub, unnameable_types)]

pub mod calibrate;
pub mod geometry;
// `identify` and `twin` are not narrowed yet: every item in them is still `pub`.
#[allow(unreachable_pub)]
pub mod identify;
pub mod onboard;
pub mod protocol;
pub mod rig;
pub mod transport;
#[allow(unreachable_pub)]
pub mod twin;

pub use calibrate::RigCalibration;
pub use rig::{LiveOptions, LiveReport, LiveSession, RigEnds};
pub use transport::{
    LinkError, PoseSource, RobotLink, SourceError, SourceOptions, open_pose_source, open_robot_link,
};
pub use twin::Twin;
