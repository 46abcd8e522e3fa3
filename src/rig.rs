//! `colcos bridge` and `colcos twin`: a scenario's behaviours driving real robots through the tracker
//! and the radio link, and the digital twin that plays the rig over the same wire formats.
use anyhow::{Context, Result, bail};
use clap::Args;
use colcos_bridge::calibrate::RigCalibration;
use colcos_bridge::protocol::swarmcon::HeaderForm;
use colcos_bridge::rig::{self, LiveOptions};
use colcos_bridge::transport::FrameServer;
use colcos_bridge::twin::{ByteChannel, CameraModel, PtyChannel, TrackerServer, Twin, UdpChannel};
use colcos_bridge::{SourceOptions, open_pose_source, open_robot_link};
use colcos_sim::scenario::Scenario;
use std::fmt::Write as _;
use std::net::SocketAddr;
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

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

#[derive(Args, Debug)]
pub struct TwinArgs {
    /// Scenario file (TOML): the arena, robots, tracker model and `[rig]` IDs.
    pub scenario: PathBuf,
    /// Address of the SwarmCon position server to serve (the bridge's swarmcon://).
    #[arg(long, default_value = "127.0.0.1:6666")]
    pub tracker: SocketAddr,
    /// The robots' end: udp://ADDR to listen on, or pty (prints the device the bridge opens).
    #[arg(long, default_value = "pty")]
    pub robots: String,
    /// The bridge's frame stream, for colour readings from what it displays.
    #[arg(long)]
    pub frames: Option<SocketAddr>,
    /// Stop after this many seconds (default: until Ctrl-C).
    #[arg(long)]
    pub duration: Option<f64>,
    /// Header form of the served blocks: plain, dot or updated (CosPhi).
    #[arg(long, default_value = "updated")]
    pub header: String,
    /// Allow serving on addresses other than loopback.
    #[arg(long)]
    pub public: bool,
    /// See the arena through a modelled overhead camera: `lab` (1.6 m up, a little off centre and
    /// tilted, markers 3.5 cm high), what `colcos calibrate screen` measures.
    #[arg(long)]
    pub camera: Option<String>,
    /// Hold every tracker block back this long, s (plus or minus --tracker-jitter).
    #[arg(long, default_value_t = 0.0)]
    pub tracker_delay: f64,
    /// Uniform jitter of the tracker delay, s.
    #[arg(long, default_value_t = 0.0)]
    pub tracker_jitter: f64,
    /// The robots' hidden true values: a file of `[[robot]]` entries (wheel scales, motor lag,
    /// command latency, sensor gain; as `[individual] file` takes) that the twin's robots drive and
    /// sense with instead of the scenario's, while the bridge assumes the scenario's.
    #[arg(long)]
    pub truth: Option<PathBuf>,
}

/// A flag that Ctrl-C and SIGTERM set.
fn stop_on_signal() -> Result<Arc<AtomicBool>> {
    let stop = Arc::new(AtomicBool::new(false));
    let s = stop.clone();
    ctrlc::set_handler(move || s.store(true, Ordering::Relaxed))
        .context("installing the Ctrl-C / SIGTERM handler")?;
    Ok(stop)
}

pub fn bridge(args: BridgeArgs, text: &mut String) -> Result<()> {
    let sc = Scenario::from_file(&args.scenario)?;
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("creating output directory {}", args.out.display()))?;
    let calibration = RigCalibration::load(&sc)?;
    let opts = SourceOptions::new(calibration.frame_transform(&sc));
    let source = open_pose_source(&args.tracker, &opts)
        .with_context(|| format!("--tracker {}", args.tracker))?;
    let link =
        open_robot_link(&args.robots).with_context(|| format!("--robots {}", args.robots))?;
    let frames = match args.frames {
        Some(addr) => Some(FrameServer::bind(addr).with_context(|| format!("--frames {addr}"))?),
        None => None,
    };
    let log = args.out.join("rig.mcap");
    let display = match args.display {
        Some(monitor) => Some(std::sync::Mutex::new(open_display(
            &sc,
            monitor,
            args.windowed,
            args.display_width,
        )?)),
        None => None,
    };
    let live_opts = LiveOptions {
        display,
        display_width: args.display_width,
        display_hz: if args.display_rate.is_finite() {
            args.display_rate
        } else {
            10.0
        },
        duration: args.duration,
        stream_width: args.frame_width.clamp(16, 7680),
        stream_hz: if args.frame_rate.is_finite() {
            args.frame_rate.clamp(1.0, 50.0)
        } else {
            25.0
        },
        log: Some(log.clone()),
        trajectory: Some(args.out.join("trajectory.csv")),
        gif: Some(args.out.join("run.gif")),
        status: !args.quiet,
        ..LiveOptions::default()
    };
    let stop = stop_on_signal()?;
    let report = rig::run(&sc, source, link, frames, live_opts, stop)?;
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

pub fn twin(args: TwinArgs, text: &mut String) -> Result<()> {
    let mut sc = Scenario::from_file(&args.scenario)?;
    if let Some(truth) = &args.truth {
        sc = sc.with_truth(truth)?;
    }
    if !args.public && !args.tracker.ip().is_loopback() {
        bail!(
            "--tracker {}: not a loopback address (add --public to serve beyond this machine)",
            args.tracker
        );
    }
    let form = match args.header.as_str() {
        "plain" => HeaderForm::Plain,
        "dot" => HeaderForm::Dot,
        "updated" => HeaderForm::Updated,
        other => bail!("--header {other:?}: must be plain, dot or updated"),
    };
    let mut tracker = TrackerServer::bind(args.tracker, form)
        .with_context(|| format!("serving the tracker on {}", args.tracker))?;
    for (key, v) in [
        ("delay", args.tracker_delay),
        ("jitter", args.tracker_jitter),
    ] {
        if !(0.0..=1.0).contains(&v) {
            bail!("--tracker-{key} {v}: must be 0 to 1 s");
        }
    }
    tracker.set_delay(args.tracker_delay, args.tracker_jitter, sc.spec.seed);
    let channel: Box<dyn ByteChannel> = if args.robots == "pty" {
        let pty = PtyChannel::open().context("opening a pseudo-terminal pair")?;
        eprintln!("robots: serial://{}?baud=115200", pty.peer_path());
        Box::new(pty)
    } else if let Some(addr) = args.robots.strip_prefix("udp://") {
        let parsed: SocketAddr = addr
            .parse()
            .with_context(|| format!("--robots {}: not an address", args.robots))?;
        if !args.public && !parsed.ip().is_loopback() {
            bail!(
                "--robots {}: not a loopback address (add --public)",
                args.robots
            );
        }
        let udp = UdpChannel::bind(addr).with_context(|| format!("--robots {}", args.robots))?;
        eprintln!("robots: udp://{}", udp.local_addr()?);
        Box::new(udp)
    } else {
        bail!("--robots {:?}: must be pty or udp://ADDR", args.robots);
    };
    eprintln!("tracker: swarmcon://{}", tracker.local_addr());
    let mut twin = Twin::new(&sc, tracker, channel, args.frames)?;
    match args.camera.as_deref() {
        None => {}
        Some("lab") => {
            let s = sc.spec.screen.size;
            let camera = CameraModel::lab([s[0] as f64, s[1] as f64]);
            twin.set_camera(Some(camera), sc.spec.seed);
        }
        Some(other) => bail!("--camera {other:?}: the camera models are: lab"),
    }
    let stop = stop_on_signal()?;
    twin.run(args.duration, &stop);
    writeln!(
        text,
        "twin ran {:.1} s of {}: {} commands received",
        twin.arena().time(),
        args.scenario.display(),
        twin.received().len()
    )?;
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
    bail!("--display {monitor}: this build has no display window (the `display` feature)")
}
