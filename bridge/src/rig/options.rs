//! What a live run is asked to do besides driving the robots, and what it measured.
use crate::protocol::colias::LegacyDrive;
use colcos_sim::shield::ShieldCounts;
use std::path::PathBuf;

/// A screen the loop shows its frames on: the window on the arena's LCD.
pub trait FrameSink: Send {
    /// Shows `frame` (row 0 at the top of the panel); false once the sink is gone (window closed).
    fn show(&mut self, frame: &image::RgbImage) -> bool;
}

/// Frames drawn from the screen: `width` px wide (the height from the panel's aspect), `hz` a second.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FrameRate {
    pub width: u32,
    pub hz: f64,
}

impl FrameRate {
    pub const fn new(width: u32, hz: f64) -> FrameRate {
        FrameRate { width, hz }
    }

    /// Frames `width` px wide, one a tick.
    pub const fn every_tick(width: u32) -> FrameRate {
        FrameRate { width, hz: 0.0 }
    }

    /// The size of a frame `width` px wide of a panel of `size` (m).
    pub(crate) fn size(width: u32, size: [f32; 2]) -> (u32, u32) {
        (
            width,
            ((width as f32) * size[1] / size[0]).round().max(1.0) as u32,
        )
    }
}

/// What a live run does besides driving the robots.
#[derive(Default)]
pub struct LiveOptions {
    /// The LCD's window, shown at `display_frames` (the window scales it to the panel; 16 to 7680
    /// px, 1 to 50 a second). The CPU draws a 4K frame of three grid pheromones in ~3 ms; Gaussian
    /// fields cost an `exp` per source and pixel, so the default is a smaller frame.
    pub display: Option<std::sync::Mutex<Box<dyn FrameSink>>>,
    pub display_frames: FrameRate,
    /// Stop after this many seconds (None: until stopped).
    pub duration: Option<f64>,
    /// The frames sent to the frame stream: width 0, none; at most one a tick, `hz` 0, every tick.
    /// Rendering costs the loop: a 960-pixel frame of two Gaussian fields takes ~10 ms on one core.
    pub stream: FrameRate,
    /// Where the rig log (MCAP) goes; None: no log.
    pub log: Option<PathBuf>,
    /// Where the trajectory CSV goes (the simulator's columns, the tracked poses as used); None: none.
    pub trajectory: Option<PathBuf>,
    /// Where the run's GIF goes (the screen with the robots at their tracked poses, one frame per
    /// `[output] gif_interval`, `gif_width` px wide, as `colcos run` draws it); None: none.
    pub gif: Option<PathBuf>,
    /// Print a status line every second.
    pub status: bool,
    /// How wheel speeds become motion commands for old firmware (`[rig] firmware = "motion"`).
    pub legacy: LegacyDrive,
}

/// What a finished live run measured.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct LiveReport {
    pub ticks: u64,
    /// Ticks in the trajectory log: those from the tracker's first pose on.
    pub logged_ticks: u64,
    pub seconds: f64,
    /// Ticks that ended after their slot.
    pub overruns: u64,
    /// Worst and 99th-percentile time of the loop's own work in a tick, ms.
    pub worst_tick_ms: f64,
    pub p99_tick_ms: f64,
    pub shield: ShieldCounts,
    /// Safety stops the watchdog sent, by kind, in order.
    pub stops: Vec<String>,
    /// Command frames the loop handed to the link.
    pub commands_sent: u64,
    /// Of those, frames that went on air, and frames a newer one for the same robot replaced while
    /// they waited for airtime (the link is newest-wins, never a growing queue).
    pub frames_on_air: u64,
    pub frames_superseded: u64,
    pub telemetry_received: u64,
    /// Robots (radio addresses) that stopped answering data requests, in the order they fell silent.
    pub silent_robots: Vec<u8>,
    /// Tracker blocks taken.
    pub pose_blocks: u64,
    /// GIF frames dropped because the encoder was busy.
    pub gif_frames_dropped: u64,
    /// The latencies the run ran with, s: the scenario's `[rig] latency` (the compensation) and
    /// `[tracker] latency` (the simulator's model of the tracker), as `colcos calibrate latency`
    /// measures them.
    pub rig_latency: f32,
    pub tracker_latency: f32,
    /// The last reason the tracker gave no poses (its address and the error), if it ever failed.
    pub tracker_problem: Option<String>,
    /// Why the robot link was failing when the run ended, if it was.
    pub link_problem: Option<String>,
    /// Ended by Ctrl-C or SIGTERM rather than by its duration.
    pub interrupted: bool,
}
