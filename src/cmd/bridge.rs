//! `colcos bridge`: a scenario's behaviours driving real robots through the tracker and the radio
//! link; the rig's ends and display window, which `colcos rig excite` opens too.
use anyhow::{Context, Result};
use clap::Args;
use colcos_bridge::calibrate::RigCalibration;
use colcos_bridge::rig::{self, FrameRate, LiveOptions, RigEnds};
use colcos_bridge::transport::FrameServer;
use colcos_bridge::{SourceOptions, open_pose_source, open_robot_link};
use colcos_sim::scenario::Scenario;
use std::fmt::Write as _;
use std::net::SocketAddr;
use std::path::{Path, PathBuf};

#[derive(Args, Debug)]
pub struct BridgeArgs {
    /// Scenario file (TOML): pheromones, behaviours and the `[rig]` section.
    pub scenario: PathBuf,
    /// Where poses come from: swarmcon://HOST:6666, udp://HOST:PORT (JSON lines) or
    /// replay://FILE[?speed=S|max].
    #[arg(long)]
    pub tracker: String,
    /// The robots' radio link: serial:///dev/ttyUSB0?baud=115200 or udp://HOST:PORT.
    #[arg(long)]
    pub robots: String,
    /// Serve the displayed frames on this address (e.g. 127.0.0.1:7700) for a twin or a viewer.
    #[arg(long)]
    pub frames: Option<SocketAddr>,
    /// Width of the served frames, px.
    #[arg(long, default_value_t = 960)]
    pub frame_width: u32,
    /// Served frames per second.
    #[arg(long, default_value_t = 25.0)]
    pub frame_rate: f64,
    /// Show the screen full screen on this monitor (the arena's LCD; monitors are listed when the
    /// window opens).
    #[arg(long)]
    pub display: Option<usize>,
    /// With --display: a window instead of full screen.
    #[arg(long)]
    pub windowed: bool,
    /// Width the screen is rendered at for the display, px (the window scales it to the monitor).
    #[arg(long, default_value_t = 960)]
    pub display_width: u32,
    /// Frames shown per second.
    #[arg(long, default_value_t = 10.0)]
    pub display_rate: f64,
    /// Stop after this many seconds (default: until Ctrl-C).
    #[arg(long)]
    pub duration: Option<f64>,
    /// Output directory: rig.mcap (everything that crossed a wire), trajectory.csv, run.gif,
    /// summary.json.
    #[arg(long, default_value = "runs/bridge")]
    pub out: PathBuf,
    /// No status line.
    #[arg(long)]
    pub quiet: bool,
}

/// Makes `out` (where a live run writes), then opens the pose source `tracker` names (mapped into
/// the arena by the scenario's rig calibration), the robots' link `robots` and, given an address,
/// the frame server. Errors name the flag.
pub(crate) fn open_rig(
    sc: &Scenario,
    out: &Path,
    tracker: &str,
    robots: &str,
    frames: Option<SocketAddr>,
) -> Result<RigEnds> {
    std::fs::create_dir_all(out)
        .with_context(|| format!("creating output directory {}", out.display()))?;
    let calibration = RigCalibration::load(sc)?;
    let opts = SourceOptions::new(calibration.frame_transform(sc));
    let source =
        open_pose_source(tracker, &opts).with_context(|| format!("--tracker {tracker}"))?;
    let link = open_robot_link(robots).with_context(|| format!("--robots {robots}"))?;
    let frames = match frames {
        Some(addr) => Some(FrameServer::bind(addr).with_context(|| format!("--frames {addr}"))?),
        None => None,
    };
    Ok(RigEnds {
        source,
        link,
        frames,
    })
}

/// The `--display` window of a live run, `width` pixels wide, when a monitor was given.
pub(crate) fn display_on(
    sc: &Scenario,
    monitor: Option<usize>,
    windowed: bool,
    width: u32,
) -> Result<Option<std::sync::Mutex<Box<dyn colcos_bridge::rig::FrameSink>>>> {
    monitor
        .map(|m| Ok(std::sync::Mutex::new(open_display(sc, m, windowed, width)?)))
        .transpose()
}

pub fn bridge(args: BridgeArgs, text: &mut String) -> Result<()> {
    let sc = Scenario::from_file(&args.scenario)?;
    let ends = open_rig(&sc, &args.out, &args.tracker, &args.robots, args.frames)?;
    let log = args.out.join("rig.mcap");
    let display = display_on(&sc, args.display, args.windowed, args.display_width)?;
    let live_opts = LiveOptions {
        display,
        display_frames: FrameRate {
            width: args.display_width,
            hz: if args.display_rate.is_finite() {
                args.display_rate
            } else {
                10.0
            },
        },
        duration: args.duration,
        stream: FrameRate {
            width: args.frame_width.clamp(16, 7680),
            hz: if args.frame_rate.is_finite() {
                args.frame_rate.clamp(1.0, 50.0)
            } else {
                25.0
            },
        },
        log: Some(log.clone()),
        trajectory: Some(args.out.join("trajectory.csv")),
        gif: Some(args.out.join("run.gif")),
        status: !args.quiet,
        ..LiveOptions::default()
    };
    let stop = super::stop_on_signal()?;
    let report = rig::run(&sc, ends, live_opts, stop)?;
    let summary = args.out.join("summary.json");
    std::fs::write(&summary, serde_json::to_string_pretty(&report)?)
        .with_context(|| format!("writing {}", summary.display()))?;
    writeln!(
        text,
        "{} ticks in {:.1} s ({} overruns; tick work worst {:.2} ms, 99th percentile {:.2} ms)",
        report.ticks, report.seconds, report.overruns, report.worst_tick_ms, report.p99_tick_ms
    )?;
    writeln!(
        text,
        "{} pose blocks, {} commands ({} on air, {} replaced by newer ones while waiting), {} telemetry frames; shield capped {} and walled {} commands; safety stops: {}",
        report.pose_blocks,
        report.commands_sent,
        report.frames_on_air,
        report.frames_superseded,
        report.telemetry_received,
        report.shield.capped,
        report.shield.walled,
        if report.stops.is_empty() {
            "none".to_string()
        } else {
            report.stops.join(", ")
        }
    )?;
    writeln!(text, "  wrote {}", log.display())?;
    writeln!(
        text,
        "  wrote {}",
        args.out.join("trajectory.csv").display()
    )?;
    writeln!(text, "  wrote {}", summary.display())?;
    let gif = args.out.join("run.gif");
    if gif.exists() {
        writeln!(text, "  wrote {}", gif.display())?;
    }
    if report.pose_blocks == 0 {
        // What ran is still reported (and written) before the failure.
        print!("{}", std::mem::take(text));
        anyhow::bail!(
            "no pose arrived from the tracker {} in {:.1} s{}",
            args.tracker,
            report.seconds,
            report
                .tracker_problem
                .as_ref()
                .map_or(String::new(), |p| format!(" ({p})"))
        );
    }
    Ok(())
}

/// The LCD's window: full screen on `monitor` (or windowed), showing each frame as it comes.
#[cfg(feature = "display")]
pub(crate) fn open_display(
    sc: &Scenario,
    monitor: usize,
    windowed: bool,
    width: u32,
) -> Result<Box<dyn colcos_bridge::rig::FrameSink>> {
    struct Window(colcos_display::Viewer);
    impl colcos_bridge::rig::FrameSink for Window {
        fn show(&mut self, frame: &image::RgbImage) -> bool {
            let size = (frame.width(), frame.height());
            let rgba = image::DynamicImage::ImageRgb8(frame.clone())
                .into_rgba8()
                .into_raw();
            self.0.show(rgba, size)
        }
    }
    let w = width.clamp(16, 7680);
    let s = sc.spec.screen.size;
    let size = (w, ((w as f32) * s[1] / s[0]).round().max(1.0) as u32);
    let opts = colcos_display::DisplayOptions {
        title: "colcos bridge".into(),
        fullscreen: !windowed,
        monitor: Some(monitor),
        // The loop paces the frames; the window must never hold it up.
        frame_period: std::time::Duration::from_millis(1),
        ..Default::default()
    };
    let viewer = colcos_display::Viewer::open(opts, size)
        .with_context(|| format!("--display {monitor}: opening the window"))?;
    Ok(Box::new(Window(viewer)))
}

#[cfg(not(feature = "display"))]
pub(crate) fn open_display(
    _: &Scenario,
    monitor: usize,
    _: bool,
    _: u32,
) -> Result<Box<dyn colcos_bridge::rig::FrameSink>> {
    anyhow::bail!("--display {monitor}: this build has no display window (the `display` feature)")
}
