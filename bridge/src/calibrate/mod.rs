//! Sim-to-real calibration of the rig, proved on the digital twin whose true values are known:
//! the screen against the camera ([`calibrate_screen`]: a homography with the markers' parallax, the
//! heading's sign and offset), the latency of each stage ([`calibrate_latency`]), and each robot's
//! colour sensors ([`calibrate_colour`]). Each runs over the rig's wire formats through a
//! [`CalibrationRig`] and writes a file that the scenario's `[rig]` section names and the bridge
//! loads ([`RigCalibration`]).
mod colour;
mod compensate;
mod latency;
mod run_colour;
mod run_latency;
mod run_screen;
mod screen;
mod session;

pub use colour::ColourCalibration;
pub use compensate::Compensation;
pub use latency::{LatencyReport, StageDelays};
pub use run_colour::{ColourRunOptions, calibrate_colour};
pub use run_latency::{LatencyRunOptions, calibrate_latency};
pub use run_screen::{ScreenRunOptions, calibrate_screen};
pub use screen::{FiducialSighting, ScreenCalibration};
// The twin's camera tests show the same fiducials the screen calibration does.
#[cfg(test)]
pub(crate) use screen::render_fiducials;
pub use session::{CalibrationRig, RawTracker};

use colcos_sim::behaviour::WheelCommand;
use colcos_sim::scenario::Scenario;
use std::path::Path;
use thiserror::Error;

#[derive(Debug, Error)]
pub enum CalibrationError {
    #[error("calibration file {path}: {reason}")]
    File { path: String, reason: String },
    #[error("calibration file {path}: `{key}` = {value}: {reason}")]
    Invalid {
        path: String,
        key: String,
        value: String,
        reason: String,
    },
    #[error("screen calibration: {0}")]
    WrongScreen(String),
    #[error("calibration fit: {0}")]
    Fit(String),
    #[error("calibration run: {0}")]
    Run(String),
    /// A calibration the scenario names under `key` (`rig.screen_calibration`) is unusable.
    #[error("`{key}`: {source}")]
    Key {
        key: &'static str,
        source: Box<CalibrationError>,
    },
}

impl CalibrationError {
    pub fn file(path: &Path, e: impl std::fmt::Display) -> CalibrationError {
        CalibrationError::File {
            path: path.display().to_string(),
            reason: e.to_string(),
        }
    }
}

/// The calibrations a scenario's `[rig]` section names, loaded and checked against its screen.
#[derive(Clone, Debug, Default)]
pub struct RigCalibration {
    pub screen: Option<ScreenCalibration>,
    pub colour: Option<ColourCalibration>,
    /// `rig.compensate`: the robots' identified wheel scales and sensor gains, undone.
    pub compensate: Option<Compensation>,
}

impl RigCalibration {
    /// Loads `rig.screen_calibration`, `rig.colour_calibration` and `rig.compensate` (relative to
    /// the scenario's directory); a screen calibration of another panel is refused.
    pub fn load(scenario: &Scenario) -> Result<RigCalibration, CalibrationError> {
        let rig = &scenario.spec.rig;
        let resolve = |p: &str| scenario.base_dir.join(p);
        let keyed = |key| {
            move |e| CalibrationError::Key {
                key,
                source: Box::new(e),
            }
        };
        let screen = match &rig.screen_calibration {
            Some(p) => {
                let load = || -> Result<ScreenCalibration, CalibrationError> {
                    let cal = ScreenCalibration::load(&resolve(p))?;
                    let s = &scenario.spec.screen;
                    cal.check_screen(s.resolution, [s.size[0] as f64, s.size[1] as f64])?;
                    Ok(cal)
                };
                Some(load().map_err(keyed("rig.screen_calibration"))?)
            }
            None => None,
        };
        let colour = match &rig.colour_calibration {
            Some(p) => {
                let path = resolve(p);
                let cal =
                    ColourCalibration::load(&path).map_err(|e| CalibrationError::file(&path, e));
                Some(cal.map_err(keyed("rig.colour_calibration"))?)
            }
            None => None,
        };
        let compensate = match &rig.compensate {
            Some(p) => {
                let robots = scenario.robot_count();
                let top = scenario.spec.robot.max_wheel_speed;
                let c = Compensation::load(&resolve(p), robots, top);
                Some(c.map_err(keyed("rig.compensate"))?)
            }
            None => None,
        };
        Ok(RigCalibration {
            screen,
            colour,
            compensate,
        })
    }

    /// Robot `index`'s (radio `radio`'s) raw counts (simulator sensor order) as the scenario's
    /// `nominal` sensor model would read the same screen, through the colour calibration's inverse
    /// or the compensation's gain and offset (the scenario names at most one; unchanged without):
    /// what the live loop hands the host with `sensors = "robot"`.
    pub fn robot_counts(
        &self,
        index: usize,
        radio: u8,
        counts: [[u16; 3]; 4],
        nominal: &colcos_sim::sensors::ColourSensor,
    ) -> [[u16; 3]; 4] {
        match (&self.colour, &self.compensate) {
            (Some(c), _) => c.to_nominal(radio, counts, nominal),
            (None, Some(c)) => c.counts(index, counts),
            (None, None) => counts,
        }
    }

    /// What robot `index` is sent for the nominal robot's command `cmd`: divided by its wheel
    /// scales under `rig.compensate`, `cmd` itself otherwise.
    pub fn robot_command(&self, index: usize, cmd: WheelCommand) -> WheelCommand {
        match &self.compensate {
            Some(c) => c.command(index, cmd),
            None => cmd,
        }
    }

    /// The tracker-to-simulator conversion for `scenario`, with the screen calibration if any.
    pub fn frame_transform(
        &self,
        scenario: &Scenario,
    ) -> crate::protocol::swarmcon::FrameTransform {
        let t = crate::protocol::swarmcon::FrameTransform::new(scenario.arena_size().y as f64);
        match &self.screen {
            Some(cal) => t.with_screen(cal.map()),
            None => t,
        }
    }
}

/// Now, UTC, as `YYYY-MM-DDTHH:MM:SSZ`.
pub(crate) fn utc_now() -> String {
    let secs = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.as_secs() as i64)
        .unwrap_or(0);
    let (days, rem) = (secs.div_euclid(86_400), secs.rem_euclid(86_400));
    // Civil date from days since 1970-01-01 (Howard Hinnant's algorithm).
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + i64::from(m <= 2);
    format!(
        "{y:04}-{m:02}-{d:02}T{:02}:{:02}:{:02}Z",
        rem / 3600,
        rem / 60 % 60,
        rem % 60
    )
}

#[cfg(test)]
mod tests {
    #[test]
    fn the_date_is_well_formed() {
        let d = super::utc_now();
        assert_eq!(d.len(), 20, "{d}");
        assert!(d.starts_with("20") && d.ends_with('Z'), "{d}");
    }
}
