//! Colour sensor calibration: each sensor's transfer curve, crosstalk, gain and dark offset (the
//! simulator's model, `colcos_sim::sensors::colour`) fitted to raw counts read under known screen
//! levels, and its calibrated inverse, per robot.
//!
//! Model, per sensor: `counts_c = dark_c + sum_k matrix[c][k] * (level_k / 255) ^ gamma`, where
//! `matrix = gain * integration_ms * crosstalk`. Gain and crosstalk only show up as their product,
//! so the file keeps the matrix and reports the gain as its mean diagonal per ms.
use super::CalibrationError;
/// The file format and the fitted model live in the simulator, which reads the screen through them.
pub use colcos_sim::sensors::ColourCalibration;
pub(crate) use colcos_sim::sensors::{RobotColour, SensorFit};
use nalgebra::{Matrix4, Vector4};
use serde::{Deserialize, Serialize};

/// Counts a channel saturates at; saturated readings are left out of the fit.
const SATURATED: f64 = 65_535.0;

/// Mean raw counts (r, g, b) of one sensor under mean screen levels (r, g, b, 0..=255).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub(crate) struct ColourSample {
    pub levels: [f64; 3],
    pub counts: [f64; 3],
}

/// Least squares of one channel at one gamma: (dark, m_r, m_g, m_b) and the sum of squares.
fn fit_channel(samples: &[ColourSample], c: usize, gamma: f64) -> Option<([f64; 4], f64)> {
    let mut ata = Matrix4::<f64>::zeros();
    let mut atb = Vector4::<f64>::zeros();
    let rows: Vec<_> = samples
        .iter()
        .filter(|s| s.counts[c] < SATURATED)
        .map(|s| {
            let l = s.levels.map(|v| (v / 255.0).clamp(0.0, 1.0).powf(gamma));
            (Vector4::new(1.0, l[0], l[1], l[2]), s.counts[c])
        })
        .collect();
    for (x, y) in &rows {
        ata += x * x.transpose();
        atb += x * *y;
    }
    let beta = ata.try_inverse()? * atb;
    let ss = rows
        .iter()
        .map(|(x, y)| (x.dot(&beta) - y).powi(2))
        .sum::<f64>();
    Some(([beta[0], beta[1], beta[2], beta[3]], ss))
}

/// Fits one sensor to its samples (ramps of each primary and black, at least): the gamma by a
/// golden-section search over [1, 4], the rest by linear least squares at each gamma.
pub(crate) fn fit_sensor(
    samples: &[ColourSample],
    integration_ms: f64,
) -> Result<SensorFit, CalibrationError> {
    if samples.len() < 8 {
        return Err(CalibrationError::Fit(format!(
            "{} colour samples: at least 8 are needed (ramps of red, green and blue)",
            samples.len()
        )));
    }
    let total = |gamma: f64| -> f64 {
        (0..3)
            .map(|c| fit_channel(samples, c, gamma).map_or(f64::INFINITY, |f| f.1))
            .sum()
    };
    let (mut a, mut b) = (1.0f64, 4.0f64);
    let r = 0.5 * (5f64.sqrt() - 1.0);
    let (mut x1, mut x2) = (b - r * (b - a), a + r * (b - a));
    let (mut f1, mut f2) = (total(x1), total(x2));
    for _ in 0..60 {
        if f1 <= f2 {
            b = x2;
            (x2, f2) = (x1, f1);
            x1 = b - r * (b - a);
            f1 = total(x1);
        } else {
            a = x1;
            (x1, f1) = (x2, f2);
            x2 = a + r * (b - a);
            f2 = total(x2);
        }
    }
    let gamma = 0.5 * (a + b);
    let mut dark = [0.0; 3];
    let mut matrix = [[0.0; 3]; 3];
    let mut ss = 0.0;
    let mut n = 0usize;
    for c in 0..3 {
        let (beta, s) = fit_channel(samples, c, gamma).ok_or_else(|| {
            CalibrationError::Fit(format!(
                "channel {} cannot be fitted: the samples do not vary each primary",
                ["r", "g", "b"][c]
            ))
        })?;
        dark[c] = beta[0];
        matrix[c] = [beta[1], beta[2], beta[3]];
        ss += s;
        n += samples.iter().filter(|s| s.counts[c] < SATURATED).count();
    }
    let gain = (matrix[0][0] + matrix[1][1] + matrix[2][2]) / 3.0 / integration_ms.max(1e-9);
    let scale = gain * integration_ms.max(1e-9);
    Ok(SensorFit {
        gamma,
        dark,
        matrix,
        gain,
        crosstalk: matrix.map(|r| r.map(|v| v / scale)),
        rms_counts: (ss / n.max(1) as f64).sqrt(),
    })
}

/// The screen levels shown for a colour calibration: black, then ramps of red, green and blue in
/// `steps` steps each (these are fitted), then mixed colours (held out, to check the fit).
pub(crate) fn ramp_levels(steps: usize) -> (Vec<[f64; 3]>, Vec<[f64; 3]>) {
    let steps = steps.max(2);
    let mut fitted = vec![[0.0; 3]];
    for k in 0..3 {
        for i in 1..=steps {
            let mut l = [0.0; 3];
            l[k] = (255.0 * i as f64 / steps as f64).round();
            fitted.push(l);
        }
    }
    let held_out = vec![
        [200.0, 120.0, 40.0],
        [60.0, 180.0, 220.0],
        [128.0, 128.0, 128.0],
        [255.0, 255.0, 255.0],
        [30.0, 90.0, 150.0],
    ];
    (fitted, held_out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use colcos_sim::rng::{Stream, stream_of};
    use colcos_sim::sensors::{ColourSensor, ColourSensorParams};

    #[test]
    fn the_model_comes_back_from_noisy_ramps() {
        let params = ColourSensorParams {
            gain: 1300.0,
            crosstalk: [[1.0, 0.12, 0.02], [0.05, 0.95, 0.14], [0.03, 0.1, 1.08]],
            dark_counts: 45.0,
            gamma: 2.35,
            ..ColourSensorParams::default()
        };
        let sensor = ColourSensor::new(params);
        let mut rng = stream_of(3, 0, Stream::Telemetry(0));
        let (fitted, held) = ramp_levels(8);
        let read = |levels: &[[f64; 3]], rng: &mut _| -> Vec<ColourSample> {
            levels
                .iter()
                .map(|l| {
                    let mut sum = [0.0; 3];
                    for _ in 0..4 {
                        let c = sensor.counts(l.map(|v| v as f32), rng);
                        for k in 0..3 {
                            sum[k] += c[k] as f64 / 4.0;
                        }
                    }
                    ColourSample {
                        levels: *l,
                        counts: sum,
                    }
                })
                .collect()
        };
        let fit = fit_sensor(&read(&fitted, &mut rng), 24.0).unwrap();
        assert!((fit.gamma - 2.35).abs() < 0.05, "{fit:?}");
        assert!((fit.gain - 1300.0 * 1.01).abs() < 30.0, "{fit:?}");
        for s in read(&held, &mut rng) {
            let p = fit.predict(s.levels);
            for c in 0..3 {
                assert!((p[c] - s.counts[c]).abs() < 40.0, "{p:?} vs {s:?}");
            }
        }
        let back = fit.intensity(sensor.counts([128.0, 64.0, 200.0], &mut rng));
        for (b, want) in back.iter().zip([128.0, 64.0, 200.0]) {
            assert!((b * 255.0 - want).abs() < 2.0, "{back:?}");
        }
    }
}
