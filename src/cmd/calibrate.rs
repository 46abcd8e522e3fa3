//! `colcos calibrate {screen,latency,colour}`: the rig's calibrations over its own wires (the
//! tracker's SwarmCon stream, the display's frame stream, the robots' radio link), each written to a
//! file that the scenario's `[rig]` section names (docs/bridge.md).
use anyhow::{Context, Result, bail};
use clap::{Args, Subcommand};
use colcos_bridge::calibrate::RigCalibration;
use colcos_bridge::calibrate::{
    CalibrationRig, ColourRunOptions, LatencyRunOptions, RawTracker, ScreenRunOptions,
    calibrate_colour, calibrate_latency, calibrate_screen,
};
use colcos_bridge::open_robot_link;
use colcos_bridge::transport::FrameServer;
use colcos_bridge::transport::PoseUrl;
use colcos_sim::scenario::Scenario;
use std::fmt::Write as _;
use std::net::SocketAddr;
use std::path::{Path, PathBuf};

#[derive(Args, Debug)]
pub struct CalibrateArgs {
    #[command(subcommand)]
    pub what: What,
}

#[derive(Subcommand, Debug)]
pub enum What {
    /// Screen <-> camera: fiducials shown at known pixels and read back from the tracker, a
    /// homography with the markers' parallax; with --robot, the heading's sign and offset from that
    /// robot driven straight in two directions.
    Screen {
        #[command(flatten)]
        common: Common,
        /// Camera height above the screen, m.
        #[arg(long, default_value_t = 1.6)]
        camera_height: f64,
        /// Marker height above the screen (on the robots), m.
        #[arg(long, default_value_t = 0.035)]
        marker_height: f64,
        /// The screen point under the camera, `X,Y` in m (default: the panel's centre).
        #[arg(long, value_parser = parse_pair)]
        nadir: Option<[f64; 2]>,
        /// Fiducial grid shown after the four corners, `COLUMNSxROWS`.
        #[arg(long, default_value = "6x4", value_parser = parse_grid)]
        grid: [usize; 2],
        /// Sightings further than this from the fit are outliers, mm.
        #[arg(long, default_value_t = 3.0)]
        threshold_mm: f64,
        /// Robot (scenario order) driven for the heading; needs --robots.
        #[arg(long)]
        robot: Option<usize>,
    },
    /// Latency per stage: capture to receipt, render to photon (a moving fiducial), and with
    /// --robot command to motion.
    Latency {
        #[command(flatten)]
        common: Common,
        /// How long to listen to the tracker, s.
        #[arg(long, default_value_t = 2.0)]
        listen: f64,
        /// Speed of the moving fiducial, m/s.
        #[arg(long, default_value_t = 0.25)]
        marker_speed: f64,
        /// Robot (scenario order) started from rest for command to motion; needs --robots.
        #[arg(long)]
        robot: Option<usize>,
        /// Write the measured `[tracker] latency` and `[rig] latency` into the scenario file (in
        /// place, its comments kept).
        #[arg(long)]
        write_scenario: bool,
    },
    /// Colour sensors: ramps of red, green and blue under the parked robots, each sensor's transfer
    /// curve, crosstalk, gain and dark counts fitted from telemetry; needs --robots.
    Colour {
        #[command(flatten)]
        common: Common,
        /// Steps of each primary's ramp.
        #[arg(long, default_value_t = 6)]
        steps: usize,
        /// Telemetry readings averaged per robot and level.
        #[arg(long, default_value_t = 2)]
        readings: usize,
    },
}

#[derive(Args, Debug)]
pub struct Common {
    /// Scenario file (TOML): the screen, the robots and their `[rig]` IDs.
    pub scenario: PathBuf,
    /// The tracker: swarmcon://HOST:PORT.
    #[arg(long)]
    pub tracker: String,
    /// The robots' radio link: serial:///dev/ttyUSB0?baud=115200 or udp://HOST:PORT.
    #[arg(long)]
    pub robots: Option<String>,
    /// Serve the patterns on this address; the display (or the twin's --frames) subscribes to it.
    #[arg(long)]
    pub frames: SocketAddr,
    /// The calibration file to write (JSON).
    #[arg(long)]
    pub out: PathBuf,
}

fn parse_pair(s: &str) -> Result<[f64; 2], String> {
    let v: Vec<f64> = s
        .split(',')
        .map(|p| p.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|e| format!("`{s}`: {e} (expected X,Y in m)"))?;
    match v[..] {
        [x, y] if x.is_finite() && y.is_finite() => Ok([x, y]),
        _ => Err(format!("`{s}`: expected two finite numbers X,Y in m")),
    }
}

fn parse_grid(s: &str) -> Result<[usize; 2], String> {
    let (a, b) = s
        .split_once('x')
        .ok_or_else(|| format!("`{s}`: expected COLUMNSxROWS, e.g. 6x4"))?;
    let n = |t: &str| {
        t.parse::<usize>()
            .ok()
            .filter(|v| (1..=40).contains(v))
            .ok_or_else(|| format!("`{s}`: columns and rows must be 1..=40"))
    };
    Ok([n(a)?, n(b)?])
}

/// Opens the tracker, the frame stream and (if given) the link.
fn open_rig(common: &Common) -> Result<(Scenario, CalibrationRig)> {
    let sc = Scenario::from_file(&common.scenario)?;
    // The output's folder exists (or is made) before anything is measured: a measurement is not
    // thrown away for a missing `calib/`.
    if let Some(dir) = common.out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).with_context(|| {
            format!("--out {}: creating {}", common.out.display(), dir.display())
        })?;
    }
    let tracker = match common
        .tracker
        .parse::<PoseUrl>()
        .with_context(|| format!("--tracker {}", common.tracker))?
    {
        PoseUrl::SwarmCon { host, port } => RawTracker::connect(&format!("{host}:{port}"))
            .with_context(|| format!("--tracker {}", common.tracker))?,
        _ => bail!(
            "--tracker {}: calibration reads the SwarmCon stream (swarmcon://HOST:PORT), where the fiducials show as unidentified slots",
            common.tracker
        ),
    };
    let frames =
        FrameServer::bind(common.frames).with_context(|| format!("--frames {}", common.frames))?;
    eprintln!(
        "showing patterns on the frame stream {}: point the display (or `colcos twin --frames`) at it",
        frames.local_addr()
    );
    let link = match &common.robots {
        Some(url) => Some(open_robot_link(url).with_context(|| format!("--robots {url}"))?),
        None => None,
    };
    Ok((sc, CalibrationRig::new(tracker, frames, link)))
}

fn write_json(path: &Path, value: &impl serde::Serialize) -> Result<()> {
    let text = serde_json::to_string_pretty(value)?;
    std::fs::write(path, text + "\n").with_context(|| format!("--out {}", path.display()))
}

pub fn main(args: CalibrateArgs, text: &mut String) -> Result<()> {
    match args.what {
        What::Screen {
            common,
            camera_height,
            marker_height,
            nadir,
            grid,
            threshold_mm,
            robot,
        } => {
            if !(marker_height >= 0.0 && camera_height > marker_height) {
                bail!(
                    "--camera-height {camera_height} / --marker-height {marker_height}: the camera must be above the markers, the markers at or above the screen"
                );
            }
            if robot.is_some() && common.robots.is_none() {
                bail!("--robot: driving a robot for the heading needs --robots");
            }
            let (sc, mut rig) = open_rig(&common)?;
            let opts = ScreenRunOptions {
                grid,
                camera_height,
                marker_height,
                nadir,
                threshold_mm,
                heading_robot: robot,
                ..ScreenRunOptions::default()
            };
            let (cal, _) = calibrate_screen(&mut rig, &sc, &opts)?;
            cal.save(&common.out)?;
            writeln!(
                text,
                "screen calibration: {} of {} fiducials kept, reprojection {:.3} mm RMS (worst {:.3} mm); heading sign {} offset {:.2} deg (spread {:.2} deg)",
                cal.inliers,
                cal.fiducials,
                cal.rms_mm,
                cal.max_mm,
                cal.heading_sign,
                cal.heading_offset_deg,
                cal.heading_rms_deg
            )?;
            writeln!(
                text,
                "  wrote {}: name it in the scenario as [rig] screen_calibration",
                common.out.display()
            )?;
        }
        What::Latency {
            common,
            listen,
            marker_speed,
            robot,
            write_scenario,
        } => {
            if robot.is_some() && common.robots.is_none() {
                bail!("--robot: starting a robot needs --robots");
            }
            // The scenario as the calibration found it: the write-back is refused if it changes.
            let before = std::fs::read_to_string(&common.scenario).ok();
            let (sc, mut rig) = open_rig(&common)?;
            let transform = RigCalibration::load(&sc)?.frame_transform(&sc);
            let opts = LatencyRunOptions {
                listen,
                marker_speed,
                motion_robot: robot,
                ..LatencyRunOptions::default()
            };
            let report = calibrate_latency(&mut rig, &sc, &transform, &opts)?;
            write_json(&common.out, &report)?;
            let ms = |s: Option<colcos_bridge::calibrate::StageDelays>| {
                s.map_or("not measured".to_string(), |s| {
                    format!(
                        "{:.1} ms (p5 {:.1}, p95 {:.1})",
                        s.median * 1e3,
                        s.p5 * 1e3,
                        s.p95 * 1e3
                    )
                })
            };
            writeln!(
                text,
                "capture to receipt: {}",
                ms(report.capture_to_receipt)
            )?;
            writeln!(text, "render to receipt:  {}", ms(report.render_to_receipt))?;
            writeln!(text, "render to photon:   {}", ms(report.render_to_photon))?;
            writeln!(text, "command to motion:  {}", ms(report.command_to_motion))?;
            match (report.tracker_latency, report.rig_latency) {
                (Some(t), Some(r)) if write_scenario => {
                    crate::scenario_write::set_numbers_unless_changed(
                        &common.scenario,
                        before.as_deref(),
                        &[("tracker", "latency", t), ("rig", "latency", r)],
                    )?;
                    writeln!(
                        text,
                        "  wrote [tracker] latency = {t:.3} (the simulator's model) and [rig] latency = {r:.3} (the compensation) into {}",
                        common.scenario.display()
                    )?;
                }
                (Some(t), Some(r)) => writeln!(
                    text,
                    "  set [tracker] latency = {t:.3} (the simulator's model) and [rig] latency = {r:.3} (the compensation), or rerun with --write-scenario"
                )?,
                _ if write_scenario => {
                    bail!(
                        "--write-scenario: the tracker's latency was not measured (no pose blocks with frame times)"
                    )
                }
                _ => {}
            }
            writeln!(text, "  wrote {}", common.out.display())?;
        }
        What::Colour {
            common,
            steps,
            readings,
        } => {
            if common.robots.is_none() {
                bail!("the colour calibration reads the robots' sensors: give --robots");
            }
            if !(2..=64).contains(&steps) || !(1..=32).contains(&readings) {
                bail!("--steps {steps} must be 2..=64 and --readings {readings} 1..=32");
            }
            let (sc, mut rig) = open_rig(&common)?;
            let opts = ColourRunOptions {
                steps,
                readings,
                ..ColourRunOptions::default()
            };
            let cal = calibrate_colour(&mut rig, &sc, &opts)?;
            cal.save(&common.out)?;
            writeln!(
                text,
                "colour calibration: {} robots, fitted {:.1} counts RMS, held-out colours {:.1} counts RMS",
                cal.robots.len(),
                cal.rms_counts,
                cal.held_out_rms_counts
            )?;
            writeln!(
                text,
                "  wrote {}: name it in the scenario as [rig] colour_calibration (and set [sensor] per_robot = true to simulate these sensors)",
                common.out.display()
            )?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pairs_and_grids_parse_and_bad_ones_say_why() {
        assert_eq!(parse_pair("0.7, 0.4").unwrap(), [0.7, 0.4]);
        assert!(parse_pair("0.7").unwrap_err().contains("X,Y"));
        assert_eq!(parse_grid("6x4").unwrap(), [6, 4]);
        assert!(parse_grid("0x4").unwrap_err().contains("1..=40"));
        assert!(parse_grid("6by4").unwrap_err().contains("COLUMNSxROWS"));
    }
}
