//! One robot's colour gain and offset: the counts it reported against the counts the nominal sensor
//! model predicts at its poses (`observed = gain * predicted + offset`, the `[individual]` model),
//! by least squares over every channel of every steady sensor reading, with the readings far off
//! the line (a pattern's edge the pose was wrong about, another robot's shadow) left out; the
//! uncertainty treats each reading's twelve channels as one draw (their errors share its pose).
//! Without enough contrast (a robot that saw one colour) the two cannot be told apart: unidentifiable.
use super::param::Param;
use super::readings::Reading;

/// Fewest steady readings and the least spread of predicted counts (sd, counts) a fit needs.
pub const MIN_READINGS: usize = 20;
pub const MIN_CONTRAST: f64 = 1000.0;

/// What the colour fit found for one robot.
#[derive(Clone, Debug)]
pub struct SensorFit {
    /// Factor on every count, with its sd.
    pub gain: Param<f64>,
    /// Counts added, with its sd.
    pub offset: Param<f64>,
    /// Readings the robot reported, and those used (steady and not left out).
    pub readings: usize,
    pub used: usize,
    /// RMS residual of the used channels, counts.
    pub rms: f64,
}

impl SensorFit {
    /// No fit, for `why`.
    pub fn none(why: &str, readings: usize) -> SensorFit {
        SensorFit {
            gain: Err(why.to_string()),
            offset: Err(why.to_string()),
            readings,
            used: 0,
            rms: f64::NAN,
        }
    }
}

/// One channel: reading index, predicted, observed.
type Point = (usize, f64, f64);

/// Fits the gain and offset from `readings`; a sensor counts as steady when its prediction moves by
/// less than `steady` counts over the pose's doubt.
pub fn fit_sensor(readings: &[Reading], steady: f64) -> SensorFit {
    if readings.is_empty() {
        return SensorFit::none(
            "unidentifiable: the log holds no telemetry from this robot at a tracked pose (the \
             bridge asks for it at [rig] telemetry_hz)",
            0,
        );
    }
    let mut points: Vec<Point> = Vec::new();
    for (r, reading) in readings.iter().enumerate() {
        for k in 0..4 {
            if reading.unsteady[k] > steady {
                continue;
            }
            for c in 0..3 {
                let (x, y) = (reading.predicted[k][c], reading.observed[k][c]);
                // Clamped counts say only that the line left the sensor's range.
                if y > 0 && y < u16::MAX && x < u16::MAX as f64 {
                    points.push((r, x, y as f64));
                }
            }
        }
    }
    let mut fit = SensorFit::none("", readings.len());
    for _ in 0..4 {
        let used = distinct(&points);
        let contrast = sd(points.iter().map(|p| p.1));
        if used < MIN_READINGS {
            let why = format!(
                "unidentifiable: only {used} of {} readings were usable (a tracked pose, a sensor \
                 clear of the pattern's edges, counts inside 1..65534); at least {MIN_READINGS} \
                 needed",
                readings.len()
            );
            return SensorFit::none(&why, readings.len());
        }
        if contrast.is_nan() || contrast < MIN_CONTRAST {
            let why = format!(
                "unidentifiable: the robot saw too little contrast (predicted counts spread \
                 {contrast:.0} (sd) over {used} steady readings; at least {MIN_CONTRAST} needed)"
            );
            return SensorFit::none(&why, readings.len());
        }
        let line = least_squares(&points);
        let res: Vec<f64> = (points.iter())
            .map(|p| (p.2 - line.0 * p.1 - line.1).abs())
            .collect();
        let mut sorted = res.clone();
        sorted.sort_by(f64::total_cmp);
        // 1.4826 x the median absolute residual: the spread without the outliers; a floor of a
        // few counts (the sensor's rounding) so that a perfect fit keeps every point.
        let cut = 4.0 * (1.4826 * sorted[sorted.len() / 2]).max(3.0);
        let before = points.len();
        let kept: Vec<Point> = (points.iter().zip(&res))
            .filter(|(_, r)| **r <= cut)
            .map(|(p, _)| *p)
            .collect();
        points = kept;
        if points.len() == before {
            break;
        }
    }
    let used = distinct(&points);
    if used < MIN_READINGS {
        return SensorFit::none(
            &format!("unidentifiable: only {used} readings agree with one line"),
            readings.len(),
        );
    }
    let line = least_squares(&points);
    let (sd_gain, sd_offset) = clustered_sd(&points, line);
    fit.used = used;
    fit.rms = (points.iter())
        .map(|p| (p.2 - line.0 * p.1 - line.1).powi(2))
        .sum::<f64>()
        .sqrt()
        / (points.len() as f64).sqrt();
    if !(sd_gain.is_finite() && sd_gain < 0.05 * line.0.abs().max(0.1)) || line.0 <= 0.0 {
        let why = format!(
            "unidentifiable: the readings do not pin the gain ({:.3} +- {sd_gain:.3})",
            line.0
        );
        fit.gain = Err(why.clone());
        fit.offset = Err(why);
    } else {
        fit.gain = Ok((line.0, sd_gain));
        fit.offset = Ok((line.1, sd_offset));
    }
    fit
}

/// How many readings the points come from.
fn distinct(points: &[Point]) -> usize {
    let mut n = 0;
    let mut last = usize::MAX;
    for p in points {
        if p.0 != last {
            n += 1;
            last = p.0;
        }
    }
    n
}

fn sd(xs: impl Iterator<Item = f64> + Clone) -> f64 {
    let n = xs.clone().count() as f64;
    if n < 2.0 {
        return 0.0;
    }
    let mean = xs.clone().sum::<f64>() / n;
    (xs.map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt()
}

/// (slope, intercept) of `observed` on `predicted`.
fn least_squares(points: &[Point]) -> (f64, f64) {
    let n = points.len() as f64;
    let (mx, my) = (
        points.iter().map(|p| p.1).sum::<f64>() / n,
        points.iter().map(|p| p.2).sum::<f64>() / n,
    );
    let sxx: f64 = points.iter().map(|p| (p.1 - mx).powi(2)).sum();
    let sxy: f64 = points.iter().map(|p| (p.1 - mx) * (p.2 - my)).sum();
    let slope = if sxx > 0.0 { sxy / sxx } else { f64::NAN };
    (slope, my - slope * mx)
}

/// Standard deviations of (slope, intercept), the sandwich estimate with one cluster per reading.
fn clustered_sd(points: &[Point], (a, b): (f64, f64)) -> (f64, f64) {
    // X'X with rows (x, 1).
    let (mut sxx, mut sx, n) = (0.0, 0.0, points.len() as f64);
    for p in points {
        sxx += p.1 * p.1;
        sx += p.1;
    }
    let det = sxx * n - sx * sx;
    if det.abs() < 1e-12 {
        return (f64::INFINITY, f64::INFINITY);
    }
    let inv = [[n / det, -sx / det], [-sx / det, sxx / det]];
    // Meat: the sum over readings of (sum x e, sum e) outer itself.
    let mut meat = [[0.0f64; 2]; 2];
    let mut k = 0;
    let clusters = distinct(points) as f64;
    while k < points.len() {
        let r = points[k].0;
        let (mut u0, mut u1) = (0.0, 0.0);
        while k < points.len() && points[k].0 == r {
            let e = points[k].2 - a * points[k].1 - b;
            u0 += points[k].1 * e;
            u1 += e;
            k += 1;
        }
        meat[0][0] += u0 * u0;
        meat[0][1] += u0 * u1;
        meat[1][1] += u1 * u1;
    }
    meat[1][0] = meat[0][1];
    // Small-sample factor G / (G - 1).
    let f = clusters / (clusters - 1.0).max(1.0);
    let v = |i: usize, j: usize| -> f64 {
        let mut s = 0.0;
        for p in 0..2 {
            for q in 0..2 {
                s += inv[i][p] * meat[p][q] * inv[q][j];
            }
        }
        f * s
    };
    (v(0, 0).max(0.0).sqrt(), v(1, 1).max(0.0).sqrt())
}
