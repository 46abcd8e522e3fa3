//! `colcos twin`: the digital twin that plays the rig (tracker, robots, camera) over the rig's own
//! wire formats for `colcos bridge` to drive.
use anyhow::{Context, Result, bail};
use clap::Args;
use colcos_bridge::protocol::swarmcon::HeaderForm;
use colcos_bridge::twin::{ByteChannel, CameraModel, PtyChannel, TrackerServer, Twin, UdpChannel};
use colcos_sim::scenario::Scenario;
use std::fmt::Write as _;
use std::net::SocketAddr;
use std::path::PathBuf;

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
    let stop = super::stop_on_signal()?;
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
