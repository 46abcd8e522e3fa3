//! `colcos calibrate screen`: fiducials shown one by one at known pixels, read back from the
//! tracker, fitted; then a robot driven straight in two directions for the heading's sign and
//! offset.
use super::CalibrationError;
use super::screen::{
    FiducialSighting, ScreenCalibration, ScreenFitOptions, fiducial_layout, fit_heading,
    fit_screen, render_fiducials,
};
use super::session::{CalibrationRig, fiducials_in, fresh_slot};
use colcos_sim::scenario::Scenario;
use image::RgbImage;
use std::time::{Duration, Instant};

#[derive(Clone, Debug, PartialEq)]
pub struct ScreenRunOptions {
    /// Columns and rows of the fiducial grid shown after the four corners.
    pub grid: [usize; 2],
    /// Width of the pattern frames sent to the display, px.
    pub frame_width: u32,
    /// Camera and marker heights above the screen, m.
    pub camera_height: f64,
    pub marker_height: f64,
    /// The screen point under the camera (our frame, m); `None`: the panel's centre.
    pub nadir: Option<[f64; 2]>,
    /// Sightings further than this from the fit, mm, are outliers.
    pub threshold_mm: f64,
    /// Tracker frames averaged per fiducial.
    pub readings: usize,
    /// Longest wait for a fiducial to appear or go, s.
    pub timeout: f64,
    /// The robot (scenario order) driven for the heading; `None`: the heading is not calibrated.
    pub heading_robot: Option<usize>,
}

impl Default for ScreenRunOptions {
    fn default() -> Self {
        ScreenRunOptions {
            grid: [6, 4],
            frame_width: 1920,
            camera_height: 1.6,
            marker_height: 0.035,
            nadir: None,
            threshold_mm: 3.0,
            readings: 3,
            timeout: 2.0,
            heading_robot: None,
        }
    }
}

/// Waits for tracker frames in which `want(fiducials)` holds, re-showing `frame` every 100 ms;
/// returns the fiducials of up to `count` distinct such frames.
fn wait_frames(
    rig: &mut CalibrationRig,
    frame: &RgbImage,
    count: usize,
    timeout: f64,
    want: impl Fn(&[[f64; 2]]) -> bool,
) -> Option<Vec<Vec<[f64; 2]>>> {
    let _ = rig.tracker.take();
    rig.show(frame);
    let (start, mut shown) = (Instant::now(), Instant::now());
    let mut got: Vec<(i64, Vec<[f64; 2]>)> = Vec::new();
    while start.elapsed().as_secs_f64() < timeout {
        for (_, block) in rig.tracker.take() {
            let f = fiducials_in(&block);
            if want(&f) && got.last().is_none_or(|(t, _)| *t != block.t_us) {
                got.push((block.t_us, f));
            }
        }
        if got.len() >= count {
            return Some(got.into_iter().map(|(_, f)| f).collect());
        }
        if shown.elapsed() > Duration::from_millis(100) {
            rig.show(frame);
            shown = Instant::now();
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    None
}

/// Shows every fiducial in turn and reads where the tracker sees it.
pub(crate) fn sight_fiducials(
    rig: &mut CalibrationRig,
    scenario: &Scenario,
    opts: &ScreenRunOptions,
) -> Result<Vec<FiducialSighting>, CalibrationError> {
    let s = &scenario.spec.screen;
    let resolution = s.resolution;
    let size = [s.size[0] as f64, s.size[1] as f64];
    let radius = scenario.spec.robot.radius as f64;
    let layout = fiducial_layout(resolution, size, radius, opts.grid);
    let width = opts.frame_width.clamp(64, 7680);
    let height = ((width as f64) * resolution[1] as f64 / resolution[0] as f64).round() as u32;
    let black = RgbImage::new(width, height);
    // Discs the size of a robot's footprint, as the SwarmCon patterns.
    let disc_px = radius * resolution[0] as f64 / size[0];
    rig.wait_for_display(Duration::from_secs_f64(opts.timeout.max(1.0) * 2.0))?;
    let mut sightings = Vec::with_capacity(layout.len());
    for (k, p) in layout.iter().enumerate() {
        wait_frames(rig, &black, 1, opts.timeout, |f| f.is_empty()).ok_or_else(|| {
            CalibrationError::Run(format!(
                "the tracker still sees calibration patterns on a black screen after {} s (before fiducial {k})",
                opts.timeout
            ))
        })?;
        let frame = render_fiducials(&[*p], disc_px, resolution, width, height);
        let seen = wait_frames(rig, &frame, opts.readings.max(1), opts.timeout, |f| f.len() == 1)
            .ok_or_else(|| {
                CalibrationError::Run(format!(
                    "fiducial {k} at screen pixel ({:.1}, {:.1}) was not seen by the tracker within {} s",
                    p[0], p[1], opts.timeout
                ))
            })?;
        let n = seen.len() as f64;
        let mean = seen
            .iter()
            .fold([0.0, 0.0], |a, f| [a[0] + f[0][0] / n, a[1] + f[0][1] / n]);
        sightings.push(FiducialSighting {
            shown: *p,
            seen: mean,
        });
    }
    rig.show(&black);
    Ok(sightings)
}

/// The whole screen calibration: fiducials, the fit, then the heading if a robot is named.
pub fn calibrate_screen(
    rig: &mut CalibrationRig,
    scenario: &Scenario,
    opts: &ScreenRunOptions,
) -> Result<(ScreenCalibration, Vec<FiducialSighting>), CalibrationError> {
    let s = &scenario.spec.screen;
    let size = [s.size[0] as f64, s.size[1] as f64];
    let sightings = sight_fiducials(rig, scenario, opts)?;
    let fit_opts = ScreenFitOptions {
        resolution: s.resolution,
        size,
        threshold_mm: opts.threshold_mm,
        camera_height: opts.camera_height,
        marker_height: opts.marker_height,
        nadir: opts.nadir.unwrap_or([0.5 * size[0], 0.5 * size[1]]),
    };
    let mut cal = fit_screen(&sightings, &fit_opts)?;
    if let Some(robot) = opts.heading_robot {
        let (sign, offset, rms) = drive_for_heading(rig, scenario, &cal, robot, opts.timeout)?;
        cal.heading_sign = sign;
        cal.heading_offset_deg = offset.to_degrees();
        cal.heading_rms_deg = rms.to_degrees();
    }
    Ok((cal, sightings))
}

/// Drives robot `robot` straight, turns it a quarter turn in place, drives it straight again, and
/// fits the heading to its track.
fn drive_for_heading(
    rig: &mut CalibrationRig,
    scenario: &Scenario,
    cal: &ScreenCalibration,
    robot: usize,
    timeout: f64,
) -> Result<(f64, f64, f64), CalibrationError> {
    let spec = &rig_spec(scenario);
    let n = scenario.spec.robots.iter().map(|g| g.count).sum::<usize>();
    if robot >= n {
        return Err(CalibrationError::Run(format!(
            "--robot {robot}: the scenario has {n} robots"
        )));
    }
    let id = spec.tracker_id(robot);
    let radio = spec
        .radio_id(robot)
        .ok_or_else(|| CalibrationError::Run(format!("robot {robot} has no radio address")))?;
    let map = cal.map();
    // Where it is now, and room to drive: two legs of ~10 cm.
    let until = Instant::now() + Duration::from_secs_f64(timeout);
    let start = loop {
        if let Some(p) = rig
            .tracker
            .take()
            .iter()
            .rev()
            .find_map(|(_, b)| fresh_slot(b, id))
        {
            break map.to_sim(p.0, p.1, p.2);
        }
        if Instant::now() > until {
            return Err(CalibrationError::Run(format!(
                "robot {robot} (marker {id}) is not seen by the tracker"
            )));
        }
        std::thread::sleep(Duration::from_millis(10));
    };
    let Some((x, y, _)) = start else {
        return Err(CalibrationError::Run(format!(
            "robot {robot}'s pose does not map onto the screen"
        )));
    };
    let arena = scenario.arena_size();
    let room = 0.15;
    if x < room || y < room || x > arena.x as f64 - room || y > arena.y as f64 - room {
        return Err(CalibrationError::Run(format!(
            "robot {robot} at ({x:.3}, {y:.3}) m has less than {room} m around it: park it further from the walls"
        )));
    }
    let speed = 0.08f32;
    let turn = 0.5 * std::f32::consts::FRAC_PI_2 * scenario.spec.robot.wheel_base / 0.05;
    let mut blocks = Vec::new();
    rig.drive(radio, speed, speed, 1.2, &mut blocks)?;
    rig.drive(radio, -0.05, 0.05, turn as f64, &mut blocks)?;
    std::thread::sleep(Duration::from_millis(200));
    rig.drive(radio, speed, speed, 1.2, &mut blocks)?;
    std::thread::sleep(Duration::from_millis(200));
    blocks.extend(rig.tracker.take());
    let mut track = Vec::new();
    let mut last = None;
    for (_, b) in &blocks {
        if last == Some(b.t_us) {
            continue;
        }
        last = Some(b.t_us);
        if let Some(p) = fresh_slot(b, id) {
            track.push(p);
        }
    }
    fit_heading(&map, &track)
}

fn rig_spec(scenario: &Scenario) -> colcos_sim::scenario::RigSpec {
    scenario.spec.rig.clone()
}
