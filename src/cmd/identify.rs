//! `colcos rig excite` and `colcos rig identify`: drive a short, bounded excitation through the
//! bridge (inside the shield, showing the scenario's screen) while it records the rig log, then fit
//! each robot's wheel scales, motor lag, command latency and colour gain and offset from that log
//! into a file of per-robot values that a scenario's `[individual] file` (and `colcos twin
//! --truth`) reads.
use super::bridge::{display_on, open_rig};
use anyhow::{Context, Result, bail};
use clap::Args;
use colcos_bridge::identify::{self, Excitation, FitOptions, Param};
use colcos_bridge::rig::{FrameRate, LiveOptions, LiveSession};
use colcos_sim::behaviour::WheelCommand;
use colcos_sim::scenario::Scenario;
use std::fmt::Write as _;
use std::path::PathBuf;

/// Longest excitation, s: the robots drive unattended meanwhile.
pub const MAX_EXCITE_SECONDS: f64 = 300.0;

#[derive(Args, Debug)]
pub struct ExciteArgs {
    /// Scenario file (TOML) with its `[rig]` section: the robots, the arena and the shield.
    pub scenario: PathBuf,
    /// Where poses come from (as `colcos bridge --tracker`).
    #[arg(long)]
    pub tracker: String,
    /// The robots' radio link (as `colcos bridge --robots`).
    #[arg(long)]
    pub robots: String,
    /// Seconds of excitation (at most 300).
    #[arg(long, default_value_t = 60.0)]
    pub seconds: f64,
    /// Largest wheel speed commanded, as a fraction of the shield's limit.
    #[arg(long, default_value_t = 0.4)]
    pub speed: f64,
    /// Show the scenario's screen full screen on this monitor (the arena's LCD) during the
    /// excitation: what the robots' colour sensors see, from which their gain is identified.
    #[arg(long)]
    pub display: Option<usize>,
    /// With --display: a window instead of full screen.
    #[arg(long)]
    pub windowed: bool,
    /// Serve the displayed frames on this address (e.g. 127.0.0.1:7700) for a twin or a viewer.
    #[arg(long)]
    pub frames: Option<std::net::SocketAddr>,
    /// Output directory: rig.mcap.
    #[arg(long, default_value = "runs/excite")]
    pub out: PathBuf,
}

#[derive(Args, Debug)]
pub struct IdentifyArgs {
    /// The rig log (`rig.mcap` of `colcos rig excite` or `colcos bridge`).
    pub log: PathBuf,
    /// The scenario the log was recorded with (its robots' radio and tracker IDs, wheel base, step).
    #[arg(long)]
    pub scenario: PathBuf,
    /// Where to write the robots' values (a file of `[[robot]]` entries for `[individual] file`).
    #[arg(long)]
    pub out: PathBuf,
    /// How much older every pose is than the age the bridge logged, s: the tracker's fastest
    /// delivery (default: the `[tracker] latency` the log was recorded with).
    #[arg(long)]
    pub pose_delay: Option<f64>,
}

/// `colcos rig excite`.
pub fn excite(args: ExciteArgs, text: &mut String) -> Result<()> {
    if !(args.seconds.is_finite() && args.seconds > 0.0 && args.seconds <= MAX_EXCITE_SECONDS) {
        bail!(
            "--seconds {}: must be in (0, {MAX_EXCITE_SECONDS}]",
            args.seconds
        );
    }
    if !(args.speed.is_finite() && args.speed > 0.0 && args.speed <= 1.0) {
        bail!(
            "--speed {}: must be a fraction in (0, 1] of the shield's wheel-speed limit",
            args.speed
        );
    }
    let sc = Scenario::from_file(&args.scenario)?;
    let limit = sc
        .spec
        .rig
        .shield
        .max_wheel_speed
        .min(sc.spec.robot.max_wheel_speed);
    // The excitation turns and drives in small circles; its commands go through the shield, which
    // keeps every robot inside the arena's virtual walls, and what the shield made of them is what
    // the log records and identification fits. An arena or shield that cannot hold it is refused
    // before anything moves.
    let max_speed = args.speed * limit as f64;
    identify::excite::check_room(&sc, max_speed)
        .map_err(|why| anyhow::anyhow!("refused: {why}"))?;
    let ends = open_rig(&sc, &args.out, &args.tracker, &args.robots, args.frames)?;
    let log = args.out.join("rig.mcap");
    let display = display_on(&sc, args.display, args.windowed, 960)?;
    let live_opts = LiveOptions {
        duration: Some(args.seconds),
        log: Some(log.clone()),
        display,
        display_frames: FrameRate::new(960, 10.0),
        stream: FrameRate::new(960, 25.0),
        ..LiveOptions::default()
    };
    let excitation = Excitation::new(sc.spec.seed, max_speed as f32);
    let n = sc.robot_count();
    let mut session = LiveSession::new(&sc, ends, live_opts)?;
    let mut overrides: Vec<Option<WheelCommand>> = vec![None; n];
    while !session.is_over() {
        let t = session.elapsed();
        for (i, o) in overrides.iter_mut().enumerate() {
            *o = Some(excitation.command(i, t));
        }
        session.tick(&overrides)?;
        session.wait_next();
    }
    let report = session.report();
    writeln!(
        text,
        "excited {n} robots for {:.1} s: {} ticks, {} pose blocks, {} commands; shield capped {} and walled {}",
        report.seconds,
        report.ticks,
        report.pose_blocks,
        report.commands_sent,
        report.shield.capped,
        report.shield.walled
    )?;
    writeln!(text, "  wrote {}", log.display())?;
    if report.pose_blocks == 0 {
        bail!("no pose arrived from the tracker {}", args.tracker);
    }
    Ok(())
}

/// `colcos rig identify`.
pub fn identify(args: IdentifyArgs, text: &mut String) -> Result<()> {
    let sc = Scenario::from_file(&args.scenario)?;
    let bytes =
        std::fs::read(&args.log).with_context(|| format!("reading {}", args.log.display()))?;
    if let Some(d) = args.pose_delay
        && !(d.is_finite() && (0.0..=1.0).contains(&d))
    {
        bail!("--pose-delay {d}: must be in [0, 1] s");
    }
    let opts = FitOptions {
        pose_delay: args.pose_delay,
        ..FitOptions::default()
    };
    let found = identify::identify(&bytes, &sc, &opts)
        .with_context(|| format!("identifying from {}", args.log.display()))?;
    writeln!(
        text,
        "{:.1} s of log; tracker latency {}",
        found.duration,
        found
            .tracker_latency
            .map_or("unknown".into(), |t| format!("{:.1} ms", 1e3 * t))
    )?;
    writeln!(
        text,
        "poses taken {:.1} ms older than their logged age (the tracker's delivery); telemetry round trip {}",
        1e3 * found.pose_delay,
        found
            .round_trip
            .map_or("none".into(), |t| format!("{:.1} ms", 1e3 * t))
    )?;
    if let Some((p, h)) = found.tracker_noise() {
        writeln!(
            text,
            "tracker noise at most {:.2} mm, {:.4} rad (the fit's residuals)",
            1e3 * p,
            h
        )?;
    }
    for f in &found.robots {
        writeln!(
            text,
            "robot {}: wheel scales {}; motor lag {}; latency {} ({} windows, {} left out as collisions)",
            f.index,
            show2(&f.wheel_scale),
            show_ms(&f.motor_lag),
            show_ms(&f.latency),
            f.windows,
            f.outliers
        )?;
        let sensor = match (&f.sensor.gain, &f.sensor.offset) {
            (Ok((g, g_sd)), Ok((o, o_sd))) => format!(
                "gain {g:.4} +- {g_sd:.4}, offset {o:.0} +- {o_sd:.0} counts ({} of {} readings, rms {:.0} counts)",
                f.sensor.used, f.sensor.readings, f.sensor.rms
            ),
            (Err(why), _) | (_, Err(why)) => why.clone(),
        };
        writeln!(text, "  colour sensor: {sensor}")?;
    }
    let file = identify::overlay::overlay(&found, &args.log.display().to_string(), &sc.spec.name);
    std::fs::write(&args.out, file.to_toml())
        .with_context(|| format!("writing {}", args.out.display()))?;
    writeln!(
        text,
        "  wrote {} (name it in the scenario as [individual] file)",
        args.out.display()
    )?;
    Ok(())
}

fn show2(p: &Param<[f64; 2]>) -> String {
    match p {
        Ok((v, sd)) => format!("{:.3} +- {:.3} / {:.3} +- {:.3}", v[0], sd[0], v[1], sd[1]),
        Err(why) => why.clone(),
    }
}

fn show_ms(p: &Param<f64>) -> String {
    match p {
        Ok((v, sd)) => format!("{:.1} +- {:.1} ms", 1e3 * v, 1e3 * sd),
        Err(why) => why.clone(),
    }
}
