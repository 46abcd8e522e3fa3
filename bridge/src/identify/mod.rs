//! System identification from a rig log (`colcos rig identify`): each robot's wheel scales, motor
//! lag and command-to-motion latency, fitted from the commands the bridge sent and the poses the
//! tracker delivered, and its colour sensor's gain and offset, fitted from the counts it reported
//! against the sensor model over the displayed field; each with its uncertainty, written as a file
//! of per-robot values that a scenario's `[individual] file` (and `colcos twin --truth`) reads.
//!
//! The files: [`series`] turns the log into each robot's commands, poses and readings, [`windows`]
//! the poses into what the robot did between captures, [`response`] the commands into what a model
//! robot would have done, [`fit`] searches the parameters, [`readings`] predicts what the sensors
//! saw, [`sensor`] fits their gain, [`overlay`] writes it all.
pub mod excite;
pub mod fit;
pub mod overlay;
pub mod param;
pub mod readings;
pub mod response;
pub mod sensor;
pub mod series;
pub mod windows;

pub use excite::Excitation;
pub use fit::{FitOptions, RobotFit, fit_robot};
pub use param::Param;
pub use sensor::{SensorFit, fit_sensor};
pub use series::{RobotSeries, SeriesError, robot_series};

use crate::rig::recorder::{read_log, read_metadata};
use crate::rig::replay;
use colcos_sim::scenario::Scenario;

/// What identification found in one log.
#[derive(Clone, Debug)]
pub struct Identified {
    pub robots: Vec<RobotFit>,
    /// The tracker's mean latency as the bridge measured it (the poses' age at arrival), s.
    pub tracker_latency: Option<f64>,
    /// Seconds of log.
    pub duration: f64,
    /// The tracker's delivery added to every pose's age ([`FitOptions::pose_delay`]), s.
    pub pose_delay: f64,
    /// Median time from a data request to its answer's arrival, s (the link both ways and the
    /// loop's tick): none without telemetry.
    pub round_trip: Option<f64>,
}

impl Identified {
    /// The tracker's noise as the fit's residuals show it, median over the robots: (position m,
    /// heading rad). A window's residual is the difference of two poses' errors, hence the `sqrt 2`;
    /// what the model misses adds to it, so these are upper bounds.
    pub fn tracker_noise(&self) -> Option<(f64, f64)> {
        let mut p: Vec<f64> = (self.robots.iter().map(|r| r.rms[1]))
            .filter(|v| v.is_finite())
            .collect();
        let mut h: Vec<f64> = (self.robots.iter().map(|r| r.rms[0]))
            .filter(|v| v.is_finite())
            .collect();
        if p.is_empty() || h.is_empty() {
            return None;
        }
        p.sort_by(f64::total_cmp);
        h.sort_by(f64::total_cmp);
        let s = std::f64::consts::SQRT_2;
        Some((p[p.len() / 2] / s, h[h.len() / 2] / s))
    }
}

#[derive(Debug, thiserror::Error)]
pub enum IdentifyError {
    #[error(transparent)]
    Series(#[from] SeriesError),
    #[error(transparent)]
    Replay(#[from] replay::ReplayError),
    #[error("predicting the colour readings: {0}")]
    Model(#[from] colcos_sim::error::SimError),
}

/// A sensor counts as steady where its predicted counts move by less than this fraction of the
/// white screen's over the pose's doubt ([`readings::POSE_DOUBT`]).
pub const STEADY_FRACTION: f64 = 0.01;

/// Identifies every robot of `scenario` from the rig log `bytes`.
pub fn identify(
    bytes: &[u8],
    scenario: &Scenario,
    opts: &FitOptions,
) -> Result<Identified, IdentifyError> {
    let metadata = read_metadata(bytes);
    series::check_scenario(&metadata, scenario)?;
    let log = read_log(bytes);
    let ticks = replay::ticks_of(&log, scenario.robot_count())?;
    let mut robots = robot_series(&ticks, scenario)?;
    let recorded = (metadata.iter().find(|(name, _)| name == "rig"))
        .and_then(|(_, rig)| rig.get("tracker_latency")?.parse::<f64>().ok());
    let pose_delay = (opts.pose_delay.or(recorded))
        .unwrap_or(scenario.spec.tracker.latency as f64)
        .clamp(0.0, 1.0);
    for r in &mut robots {
        for p in &mut r.poses {
            p.0 -= pose_delay;
        }
    }
    let mut trips: Vec<f64> = (robots.iter())
        .flat_map(|r| r.answers.iter().map(|(sent, _, got)| got - sent))
        .collect();
    trips.sort_by(f64::total_cmp);
    let round_trip = trips.get(trips.len() / 2).copied();
    let ages: Vec<f64> = ticks
        .iter()
        .flat_map(|t| t.poses.iter().filter(|p| p.fresh).map(|p| p.age))
        .filter(|a| a.is_finite())
        .collect();
    let tracker_latency = (!ages.is_empty()).then(|| ages.iter().sum::<f64>() / ages.len() as f64);
    let duration = ticks.last().map_or(0.0, |t| t.t) - ticks.first().map_or(0.0, |t| t.t);
    let opts = FitOptions {
        wheel_base: scenario.spec.robot.wheel_base as f64,
        step: scenario.spec.dt as f64,
        ..*opts
    };
    let (readings, white) = readings::predict_readings(&ticks, scenario, &robots)?;
    let mut fits: Vec<RobotFit> = std::thread::scope(|s| {
        let handles: Vec<_> = robots
            .iter()
            .enumerate()
            .map(|(i, r)| s.spawn(move || fit_robot(i, &r.commands, &r.poses, &opts)))
            .collect();
        handles
            .into_iter()
            .map(|h| h.join().expect("a fit panicked"))
            .collect()
    });
    for (f, r) in fits.iter_mut().zip(&readings) {
        f.sensor = fit_sensor(r, STEADY_FRACTION * white);
    }
    Ok(Identified {
        robots: fits,
        tracker_latency,
        duration,
        pose_delay,
        round_trip,
    })
}
