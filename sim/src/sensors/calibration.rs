//! The per-robot colour calibration file (`colcos calibrate colour` writes it, JSON): each robot's four
//! fitted sensor models. The bridge maps a robot's raw counts through it onto the nominal sensor's;
//! the simulator, with `[sensor] per_robot = true`, reads the screen through it (the rig's sensors).
//!
//! Model, per sensor: `counts_c = dark_c + sum_k matrix[c][k] * (level_k / 255) ^ gamma`, where
//! `matrix = gain * integration_ms * crosstalk`. Gain and crosstalk only show up as their product,
//! so the file keeps the matrix and reports the gain as its mean diagonal per ms.
use super::colour::{ColourSensor, ColourSensorParams, invert3};
use crate::error::{Result, SimError};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// Counts a channel saturates at.
const SATURATED: f64 = 65_535.0;

/// One sensor's fitted model.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SensorFit {
    pub gamma: f64,
    pub dark: [f64; 3],
    /// counts_c per unit light of primary k (gain x integration time x crosstalk).
    pub matrix: [[f64; 3]; 3],
    /// Counts per unit light per ms (the mean of the matrix's diagonal over the integration time).
    pub gain: f64,
    /// The matrix over gain x integration time.
    pub crosstalk: [[f64; 3]; 3],
    /// Root mean square residual of the samples fitted, counts.
    pub rms_counts: f64,
}

impl SensorFit {
    /// A sensor's model from its parts (a datasheet's or a twin's known values): the matrix is
    /// `gain x integration_ms x crosstalk`; no fit, so no residual.
    pub fn from_parts(
        gamma: f64,
        gain: f64,
        crosstalk: [[f64; 3]; 3],
        dark: [f64; 3],
        integration_ms: f64,
    ) -> SensorFit {
        SensorFit {
            gamma,
            dark,
            matrix: crosstalk.map(|r| r.map(|v| v * gain * integration_ms)),
            gain,
            crosstalk,
            rms_counts: 0.0,
        }
    }

    /// The counts the model predicts for `levels` (without noise or saturation).
    pub fn predict(&self, levels: [f64; 3]) -> [f64; 3] {
        let light = levels.map(|l| (l / 255.0).clamp(0.0, 1.0).powf(self.gamma));
        std::array::from_fn(|c| {
            self.dark[c] + (0..3).map(|k| self.matrix[c][k] * light[k]).sum::<f64>()
        })
    }

    /// Screen intensity (level / 255) per primary from raw counts: the calibrated inverse.
    pub fn intensity(&self, counts: [u16; 3]) -> [f64; 3] {
        let m = self.matrix.map(|r| r.map(|v| v as f32));
        let Some(inv) = invert3(&m) else {
            return [0.0; 3];
        };
        let signal: [f64; 3] = std::array::from_fn(|c| counts[c] as f64 - self.dark[c]);
        std::array::from_fn(|k| {
            let light: f64 = (0..3).map(|c| inv[k][c] as f64 * signal[c]).sum();
            if counts[k] as f64 >= SATURATED {
                1.0
            } else {
                light.clamp(0.0, 1.0).powf(1.0 / self.gamma)
            }
        })
    }

    /// The simulator's sensor parameters for this sensor (the rest from `base`); its dark counts
    /// per channel are [`SensorFit::sensor`]'s, the mean here.
    pub fn params(&self, base: &ColourSensorParams) -> ColourSensorParams {
        ColourSensorParams {
            gamma: self.gamma as f32,
            crosstalk: self.crosstalk.map(|r| r.map(|v| v as f32)),
            gain: self.gain as f32,
            dark_counts: (self.dark.iter().sum::<f64>() / 3.0) as f32,
            ..*base
        }
    }

    /// This sensor as the simulator's model (footprint, integration time and noise from `base`, the
    /// gain times `gain_factor`, `crosstalk_offset` added off the diagonal, floored at 0): the
    /// `[randomize]` draws on top of the fitted sensor).
    pub fn sensor(
        &self,
        base: &ColourSensorParams,
        gain_factor: f32,
        crosstalk_offset: &[[f32; 3]; 3],
    ) -> ColourSensor {
        let mut p = self.params(base);
        p.gain *= gain_factor;
        for (c, row) in p.crosstalk.iter_mut().enumerate() {
            for (k, v) in row.iter_mut().enumerate() {
                // A fitted entry may be slightly negative: only a drawn offset is floored.
                if c != k && crosstalk_offset[c][k] != 0.0 {
                    *v = (*v + crosstalk_offset[c][k]).max(0.0);
                }
            }
        }
        ColourSensor::with_dark(p, self.dark.map(|d| d as f32))
    }
}

/// One robot's four sensors, in the simulator's order (right, front, left, back).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RobotColour {
    pub radio_id: u8,
    pub sensors: [SensorFit; 4],
}

/// What a colour calibration file holds (JSON).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ColourCalibration {
    pub date: String,
    /// The sensors' integration time the counts were taken at, ms.
    pub integration_ms: f64,
    pub robots: Vec<RobotColour>,
    /// Root mean square residual over every sensor's fitted samples, counts.
    pub rms_counts: f64,
    /// The same over samples held out of the fit (other colours than the ramps), counts.
    pub held_out_rms_counts: f64,
}

impl ColourCalibration {
    /// A calibration dated `date` (UTC, ISO 8601) of `robots`, its fit residual from theirs.
    pub fn new(
        date: String,
        integration_ms: f64,
        robots: Vec<RobotColour>,
        held_out_rms_counts: f64,
    ) -> Self {
        let fits: Vec<_> = robots.iter().flat_map(|r| r.sensors.iter()).collect();
        let ms = fits.iter().map(|f| f.rms_counts.powi(2)).sum::<f64>() / fits.len().max(1) as f64;
        ColourCalibration {
            date,
            integration_ms,
            robots,
            rms_counts: ms.sqrt(),
            held_out_rms_counts,
        }
    }

    pub fn robot(&self, radio_id: u8) -> Option<&RobotColour> {
        self.robots.iter().find(|r| r.radio_id == radio_id)
    }

    pub fn save(&self, path: &Path) -> Result<()> {
        let text = serde_json::to_string_pretty(self).map_err(|e| SimError::Parse {
            path: path.display().to_string(),
            message: e.to_string(),
        })?;
        std::fs::write(path, text + "\n")
            .map_err(|e| SimError::io(format!("writing {}", path.display()), e))
    }

    /// Reads and checks a file: every sensor needs a gamma > 0 and an invertible matrix.
    pub fn load(path: &Path) -> Result<ColourCalibration> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| SimError::io(format!("reading {}", path.display()), e))?;
        let cal: ColourCalibration = serde_json::from_str(&text).map_err(|e| SimError::Parse {
            path: path.display().to_string(),
            message: format!("not a colour calibration file: {e}"),
        })?;
        for (i, r) in cal.robots.iter().enumerate() {
            for (k, s) in r.sensors.iter().enumerate() {
                let m = s.matrix.map(|r| r.map(|v| v as f32));
                let finite = s
                    .dark
                    .iter()
                    .chain(s.matrix.iter().flatten())
                    .all(|v| v.is_finite());
                if !(s.gamma.is_finite() && s.gamma > 0.0 && finite) || invert3(&m).is_none() {
                    return Err(SimError::invalid(
                        format!("{}: robots[{i}].sensors[{k}]", path.display()),
                        format!(
                            "gamma {}, dark {:?}, matrix {:?}",
                            s.gamma, s.dark, s.matrix
                        ),
                        "needs a gamma > 0, finite dark counts and an invertible matrix",
                    ));
                }
            }
        }
        Ok(cal)
    }

    /// Robot `radio_id`'s raw counts (simulator order) as the `nominal` sensor model would read the
    /// same screen: through this robot's calibrated inverse, then the nominal model without noise.
    /// A robot not in the file keeps its counts.
    pub fn to_nominal(
        &self,
        radio_id: u8,
        counts: [[u16; 3]; 4],
        nominal: &ColourSensor,
    ) -> [[u16; 3]; 4] {
        let Some(robot) = self.robot(radio_id) else {
            return counts;
        };
        let p = nominal.params();
        std::array::from_fn(|s| {
            let intensity = robot.sensors[s].intensity(counts[s]);
            let light = nominal.light(intensity.map(|v| (v * 255.0) as f32));
            std::array::from_fn(|c| {
                let signal: f32 = (0..3).map(|k| p.crosstalk[c][k] * light[k]).sum();
                (p.dark_counts + p.gain * p.integration_ms * signal)
                    .round()
                    .clamp(0.0, 65_535.0) as u16
            })
        })
    }
}
