//! `colcos calibrate latency`: listens to the tracker (capture to receipt), moves a fiducial across
//! the screen at a known speed (render to photon), and starts a parked robot (command to motion).
use super::latency::{
    BlockTiming, LatencyReport, MarkerSighting, StageDelays, capture_to_receipt, command_to_motion,
    moving_marker,
};
use super::screen::render_fiducials;
use super::session::{CalibrationRig, fiducials_in, fresh_slot};
use super::{CalibrationError, utc_now};
use crate::protocol::swarmcon::FrameTransform;
use colcos_sim::scenario::Scenario;
use std::time::{Duration, Instant};

#[derive(Clone, Debug, PartialEq)]
pub struct LatencyRunOptions {
    /// How long to listen to the tracker's blocks, s.
    pub listen: f64,
    /// The moving fiducial's speed, m/s, and how long it moves, s (0: not measured).
    pub marker_speed: f64,
    pub marker_seconds: f64,
    /// Width of the frames that show it, px.
    pub frame_width: u32,
    /// The robot (scenario order) started for command to motion (`None`: not measured), its speed,
    /// m/s, and the number of starts.
    pub motion_robot: Option<usize>,
    pub motion_speed: f32,
    pub motion_trials: usize,
}

impl Default for LatencyRunOptions {
    fn default() -> Self {
        LatencyRunOptions {
            listen: 2.0,
            marker_speed: 0.25,
            marker_seconds: 2.0,
            frame_width: 480,
            motion_robot: None,
            motion_speed: 0.1,
            motion_trials: 3,
        }
    }
}

/// Every stage `opts` asks for; `transform` converts tracker coordinates (the bridge's, with the
/// screen calibration if there is one).
pub fn calibrate_latency(
    rig: &mut CalibrationRig,
    scenario: &Scenario,
    transform: &FrameTransform,
    opts: &LatencyRunOptions,
) -> Result<LatencyReport, CalibrationError> {
    let mut report = LatencyReport {
        date: utc_now(),
        ..LatencyReport::default()
    };
    // Capture to receipt.
    let _ = rig.tracker.take();
    std::thread::sleep(Duration::from_secs_f64(opts.listen.clamp(0.2, 600.0)));
    let blocks: Vec<_> = rig
        .tracker
        .take()
        .iter()
        .map(|(receipt, b)| BlockTiming {
            frame_t: b.t_us as f64 * 1e-6,
            receipt: *receipt,
        })
        .collect();
    let (stage, offset) = capture_to_receipt(&blocks).ok_or_else(|| {
        CalibrationError::Run(format!(
            "no tracker blocks in {} s of listening",
            opts.listen
        ))
    })?;
    report.capture_to_receipt = Some(stage);
    report.clock_offset = Some(offset);
    if offset.abs() > 1.0 {
        log::warn!(
            "the tracker's clock is {offset:.3} s off this machine's: capture to receipt assumes the clocks agree, and render to photon is then unknown"
        );
    }
    if opts.marker_speed > 0.0 && opts.marker_seconds > 0.0 {
        let (total, photon) = run_marker(rig, scenario, transform, opts)?;
        report.render_to_receipt = Some(total);
        if offset.abs() <= 1.0 {
            report.render_to_photon = Some(photon);
        }
    }
    if let Some(robot) = opts.motion_robot {
        report.command_to_motion = Some(run_motion(rig, scenario, transform, robot, opts)?);
    }
    report.tracker_latency = report.capture_to_receipt.map(|s| s.median);
    report.rig_latency = Some(
        offset.clamp(0.0, 0.5)
            + report
                .render_to_photon
                .map(|s| s.median.max(0.0))
                .unwrap_or(0.0),
    );
    Ok(report)
}

/// A fiducial moving along x at mid-height; the tracker's sightings against where it was drawn.
fn run_marker(
    rig: &mut CalibrationRig,
    scenario: &Scenario,
    transform: &FrameTransform,
    opts: &LatencyRunOptions,
) -> Result<(StageDelays, StageDelays), CalibrationError> {
    let s = &scenario.spec.screen;
    let size = [s.size[0] as f64, s.size[1] as f64];
    let resolution = s.resolution;
    let width = opts.frame_width.clamp(64, 7680);
    let height = ((width as f64) * resolution[1] as f64 / resolution[0] as f64).round() as u32;
    let radius_px = scenario.spec.robot.radius as f64 * resolution[0] as f64 / size[0];
    let travel = opts.marker_speed * opts.marker_seconds;
    if travel > size[0] - 0.2 {
        return Err(CalibrationError::Run(format!(
            "the marker would travel {travel:.2} m at {} m/s for {} s: more than the {:.2} m screen allows",
            opts.marker_speed, opts.marker_seconds, size[0]
        )));
    }
    let (x0, y) = (0.1, 0.5 * size[1]);
    let to_px = |x: f64| {
        [
            x / size[0] * resolution[0] as f64,
            (size[1] - y) / size[1] * resolution[1] as f64,
        ]
    };
    rig.wait_for_display(Duration::from_secs(4))?;
    // Held at the start until the tracker sees it, so the first sightings are not of a jump.
    let first = render_fiducials(&[to_px(x0)], radius_px, resolution, width, height);
    let until = Instant::now() + Duration::from_secs(2);
    loop {
        rig.show(&first);
        std::thread::sleep(Duration::from_millis(40));
        if rig
            .tracker
            .take()
            .iter()
            .any(|(_, b)| fiducials_in(b).len() == 1)
        {
            break;
        }
        if Instant::now() > until {
            return Err(CalibrationError::Run(
                "the moving fiducial is not seen by the tracker".into(),
            ));
        }
    }
    let start = Instant::now();
    let t0 = crate::transport::epoch_s();
    let mut sightings = Vec::new();
    let mut collect = |rig: &mut CalibrationRig| {
        for (receipt, b) in rig.tracker.take() {
            if let [f] = fiducials_in(&b)[..] {
                let (x, _, _) = transform.to_sim_f64(f[0], f[1], 0.0);
                if x.is_finite() {
                    sightings.push(MarkerSighting {
                        receipt,
                        capture: b.t_us as f64 * 1e-6,
                        position: x,
                    });
                }
            }
        }
    };
    while start.elapsed().as_secs_f64() < opts.marker_seconds {
        // Drawn where it is at the moment of showing, on this machine's clock.
        let x = x0 + opts.marker_speed * (crate::transport::epoch_s() - t0);
        rig.show(&render_fiducials(
            &[to_px(x)],
            radius_px,
            resolution,
            width,
            height,
        ));
        collect(rig);
        std::thread::sleep(Duration::from_millis(20));
    }
    std::thread::sleep(Duration::from_millis(300));
    collect(rig);
    rig.show(&image::RgbImage::new(width, height));
    // Sightings of the held start position say nothing about the lag.
    sightings.retain(|s| s.position > x0 + 0.01);
    moving_marker(&sightings, t0, x0, opts.marker_speed).ok_or_else(|| {
        CalibrationError::Run("the tracker did not follow the moving fiducial".into())
    })
}

/// Starts robot `robot` from rest a few times (forward, back, ...) and times its first movement.
fn run_motion(
    rig: &mut CalibrationRig,
    scenario: &Scenario,
    transform: &FrameTransform,
    robot: usize,
    opts: &LatencyRunOptions,
) -> Result<StageDelays, CalibrationError> {
    let spec = &scenario.spec.rig;
    let id = spec.tracker_id(robot);
    let radio = spec
        .radio_id(robot)
        .ok_or_else(|| CalibrationError::Run(format!("robot {robot} has no radio address")))?;
    let lag = scenario.spec.robot.motor_lag as f64;
    let pos = |b: &crate::protocol::swarmcon::TrackerFrame| {
        fresh_slot(b, id).map(|(x, y, yaw)| {
            let (x, y, _) = transform.to_sim_f64(x, y, yaw);
            (b.t_us as f64 * 1e-6, x, y)
        })
    };
    let mut delays = Vec::new();
    for trial in 0..opts.motion_trials.max(1) {
        rig.stop_all()?;
        std::thread::sleep(Duration::from_millis(300));
        let _ = rig.tracker.take();
        std::thread::sleep(Duration::from_millis(300));
        let rest: Vec<_> = rig
            .tracker
            .take()
            .iter()
            .filter_map(|(_, b)| pos(b))
            .collect();
        if rest.is_empty() {
            return Err(CalibrationError::Run(format!(
                "robot {robot} (marker {id}) is not seen by the tracker"
            )));
        }
        let n = rest.len() as f64;
        let (rx, ry) = rest
            .iter()
            .fold((0.0, 0.0), |a, p| (a.0 + p.1 / n, a.1 + p.2 / n));
        let speed = if trial % 2 == 0 {
            opts.motion_speed
        } else {
            -opts.motion_speed
        };
        let sent = crate::transport::epoch_s();
        let mut blocks = Vec::new();
        rig.drive(radio, speed, speed, 0.5, &mut blocks)?;
        let track: Vec<_> = blocks
            .iter()
            .filter_map(|(_, b)| pos(b))
            .map(|(t, x, y)| (t, (x - rx).hypot(y - ry)))
            .collect();
        let d =
            command_to_motion(sent, &track, 0.005, speed.abs() as f64, lag).ok_or_else(|| {
                CalibrationError::Run(format!("robot {robot} did not move when told to"))
            })?;
        delays.push(d);
    }
    rig.stop_all()?;
    Ok(StageDelays::of(&delays).unwrap_or_default())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_marker_fits_the_panel() {
        let o = LatencyRunOptions::default();
        assert!(o.marker_speed * o.marker_seconds < 1.2);
    }
}
