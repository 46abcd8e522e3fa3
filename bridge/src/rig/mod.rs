//! The rig loop: at the screen's 20 ms, the latest poses -> injection at the tracked poses (latency
//! compensated) -> field step -> screen -> the display sinks -> observations -> behaviours -> the
//! shield -> wheel commands -> the link. A watchdog thread beside it stops the robots when the loop
//! cannot be trusted to, and a guard stops them whichever way the loop ends.
//!
//! [`LoopCore`] is one tick as a function of its inputs, stepping the [`HostWorld`] (the simulator's
//! stages with the real arena); [`LiveSession`] gives it the real clock, tracker, link, screen and
//! logs; [`recorder`] writes the rig log and reads it back; [`replay`] gives the core a recorded
//! run's inputs instead.

mod core;
mod gif_thread;
mod host;
mod onboard_supervisor;
mod options;
pub mod recorder;
pub mod replay;
mod session;
mod stopper;
mod watchdog;

pub use core::{CoreCounters, LoopCore, PoseIn, TickInput};
pub use host::HostWorld;
pub use options::{FrameRate, FrameSink, LiveOptions, LiveReport};
pub use session::LiveSession;

use crate::transport::{FrameServer, PoseSource, RobotLink};
use colcos_sim::error::Result;
use colcos_sim::scenario::Scenario;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

/// The ends of the rig a live run talks through.
pub struct RigEnds {
    pub source: Box<dyn PoseSource>,
    pub link: Box<dyn RobotLink>,
    /// The server the displayed frames go out on, when asked for.
    pub frames: Option<FrameServer>,
}

/// Runs the live loop on `scenario`'s robots, their behaviours deciding, until `stop` is set or the
/// duration is over; every robot is stopped when it returns (or unwinds).
pub fn run(
    scenario: &Scenario,
    ends: RigEnds,
    opts: LiveOptions,
    stop: Arc<AtomicBool>,
) -> Result<LiveReport> {
    let status = opts.status;
    let mut session = LiveSession::new(scenario, ends, opts)?;
    while !stop.load(Ordering::Relaxed) && !session.is_over() {
        session.tick(&[])?;
        session.wait_next();
    }
    if status {
        eprintln!();
    }
    let mut report = session.report();
    report.interrupted = stop.load(Ordering::Relaxed);
    Ok(report)
}
