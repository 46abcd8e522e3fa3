//! `colcos calibrate colour`: the robots parked, the whole screen shown at black, then ramps of red,
//! green and blue, then a few mixed colours; each robot's raw counts read from telemetry at every
//! level; each sensor's model fitted to the ramps and checked on the mixed colours.
use super::CalibrationError;
use super::colour::{
    ColourCalibration, ColourSample, RobotColour, SensorFit, fit_sensor, ramp_levels,
};
use super::session::CalibrationRig;
use crate::protocol::colias::{HostCommand, colour_to_sim};
use colcos_sim::scenario::Scenario;
use image::{Rgb, RgbImage};
use std::time::{Duration, Instant};

#[derive(Clone, Debug, PartialEq)]
pub struct ColourRunOptions {
    /// Steps of each primary's ramp (black is shown once).
    pub steps: usize,
    /// Telemetry readings averaged per robot and level.
    pub readings: usize,
    /// Wait after a new level is shown before reading, s (the LCD's response and one integration).
    pub settle: f64,
    /// Longest wait for a robot's answer, s.
    pub timeout: f64,
}

impl Default for ColourRunOptions {
    fn default() -> Self {
        ColourRunOptions {
            steps: 6,
            readings: 2,
            settle: 0.15,
            timeout: 0.5,
        }
    }
}

/// Each robot's raw counts (simulator sensor order) at `levels`, averaged over `readings`.
fn read_level(
    rig: &mut CalibrationRig,
    radio: &[u8],
    levels: [f64; 3],
    opts: &ColourRunOptions,
) -> Result<Vec<[[f64; 3]; 4]>, CalibrationError> {
    let frame = RgbImage::from_pixel(
        64,
        36,
        Rgb(levels.map(|l| l.round().clamp(0.0, 255.0) as u8)),
    );
    rig.show(&frame);
    std::thread::sleep(Duration::from_secs_f64(opts.settle));
    rig.show(&frame);
    let mut sums = vec![[[0.0f64; 3]; 4]; radio.len()];
    let mut got = vec![0usize; radio.len()];
    let link_err =
        |e: crate::transport::LinkError| CalibrationError::Run(format!("robot link: {e}"));
    for (i, &id) in radio.iter().enumerate() {
        let link = rig.link.as_mut().ok_or_else(|| {
            CalibrationError::Run("the colour calibration reads robots: give --robots".into())
        })?;
        let _ = link.take_telemetry();
        for _ in 0..opts.readings.max(1) {
            rig.command(id, HostCommand::RequestTelemetry(1))?;
            let until = Instant::now() + Duration::from_secs_f64(opts.timeout);
            let before = got[i];
            while got[i] == before && Instant::now() < until {
                std::thread::sleep(Duration::from_millis(2));
                let link = rig
                    .link
                    .as_mut()
                    .ok_or_else(|| CalibrationError::Run("the robot link went away".into()))?;
                link.pump().map_err(link_err)?;
                for tm in link.take_telemetry() {
                    if tm.id != id {
                        continue;
                    }
                    let counts = colour_to_sim(tm.colour);
                    for (s, c) in sums[i].iter_mut().zip(counts) {
                        for k in 0..3 {
                            s[k] += c[k] as f64;
                        }
                    }
                    got[i] += 1;
                }
            }
        }
        if got[i] == 0 {
            return Err(CalibrationError::Run(format!(
                "robot with radio address {id} did not answer a data request within {} s",
                opts.timeout
            )));
        }
    }
    Ok(sums
        .iter()
        .zip(&got)
        .map(|(s, &n)| s.map(|c| c.map(|v| v / n as f64)))
        .collect())
}

/// Runs the ramps and fits every robot of `scenario` (all of them parked on the screen).
pub fn calibrate_colour(
    rig: &mut CalibrationRig,
    scenario: &Scenario,
    opts: &ColourRunOptions,
) -> Result<ColourCalibration, CalibrationError> {
    let n = scenario.spec.robots.iter().map(|g| g.count).sum::<usize>();
    let radio = scenario
        .spec
        .rig
        .radio_addresses(n)
        .map_err(|e| CalibrationError::Run(e.to_string()))?;
    rig.wait_for_display(Duration::from_secs(4))?;
    rig.stop_all()?;
    let (fitted, held_out) = ramp_levels(opts.steps);
    let mut samples = vec![[(); 4].map(|_| Vec::new()); n];
    for levels in &fitted {
        for (r, counts) in read_level(rig, &radio, *levels, opts)?
            .into_iter()
            .enumerate()
        {
            for (s, c) in counts.into_iter().enumerate() {
                samples[r][s].push(ColourSample {
                    levels: *levels,
                    counts: c,
                });
            }
        }
    }
    let mut held = vec![Vec::new(); n];
    for levels in &held_out {
        for (r, counts) in read_level(rig, &radio, *levels, opts)?
            .into_iter()
            .enumerate()
        {
            held[r].push((*levels, counts));
        }
    }
    rig.show(&RgbImage::new(64, 36));
    let integration_ms = scenario.spec.sensor.integration_ms as f64;
    let mut robots = Vec::with_capacity(n);
    let (mut ss, mut count) = (0.0, 0usize);
    for r in 0..n {
        let mut sensors = Vec::with_capacity(4);
        for (s, fit_samples) in samples[r].iter().enumerate() {
            let fit = fit_sensor(fit_samples, integration_ms).map_err(|e| {
                CalibrationError::Fit(format!("robot {r} (radio {}) sensor {s}: {e}", radio[r]))
            })?;
            for (levels, counts) in &held[r] {
                let p = fit.predict(*levels);
                for c in 0..3 {
                    if counts[s][c] < 65_535.0 {
                        ss += (p[c] - counts[s][c]).powi(2);
                        count += 1;
                    }
                }
            }
            sensors.push(fit);
        }
        let sensors: [SensorFit; 4] = sensors
            .try_into()
            .map_err(|_| CalibrationError::Fit("four sensors expected".into()))?;
        robots.push(RobotColour {
            radio_id: radio[r],
            sensors,
        });
    }
    Ok(ColourCalibration::new(
        super::utc_now(),
        integration_ms,
        robots,
        (ss / count.max(1) as f64).sqrt(),
    ))
}
