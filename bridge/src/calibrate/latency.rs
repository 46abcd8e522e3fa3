//! Latency, stage by stage, from what crosses the wires:
//!
//! - **capture to receipt**: each tracker block's frame time (the camera's capture, on the
//!   tracker's clock) against the moment it arrived here. With the clocks in step (one machine, or
//!   NTP) that difference is the latency; [`crate::transport::ClockOffset`] gives the fastest delivery,
//!   which is what the live loop's pose ages leave out.
//! - **render to photon**: a fiducial moving at a known speed on the screen; where the tracker
//!   sees it lags where it was drawn by `offset / speed` seconds.
//! - **command to motion seen**: a parked robot sent a forward command; when its tracked position
//!   starts to move, less the time the motor model needs to cover the detection threshold.
use crate::transport::ClockOffset;
use serde::{Deserialize, Serialize};

/// A distribution of delays, s.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct StageDelays {
    pub median: f64,
    pub mean: f64,
    /// 5th and 95th percentiles.
    pub p5: f64,
    pub p95: f64,
    /// Standard deviation.
    pub std: f64,
    pub samples: usize,
}

impl StageDelays {
    /// `None` without samples.
    pub fn of(values: &[f64]) -> Option<StageDelays> {
        let mut v: Vec<f64> = values.iter().copied().filter(|x| x.is_finite()).collect();
        if v.is_empty() {
            return None;
        }
        v.sort_by(f64::total_cmp);
        let n = v.len();
        let at = |q: f64| v[((q * (n - 1) as f64).round() as usize).min(n - 1)];
        let mean = v.iter().sum::<f64>() / n as f64;
        let var = v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n as f64;
        Some(StageDelays {
            median: at(0.5),
            mean,
            p5: at(0.05),
            p95: at(0.95),
            std: var.sqrt(),
            samples: n,
        })
    }
}

/// A tracker block: its frame time (tracker clock, epoch s) and when it arrived (host epoch s).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct BlockTiming {
    pub frame_t: f64,
    pub receipt: f64,
}

/// Capture to receipt, and the clock offset estimate (`receipt - frame_t` at its fastest).
pub(crate) fn capture_to_receipt(blocks: &[BlockTiming]) -> Option<(StageDelays, f64)> {
    let mut clock = ClockOffset::default();
    let mut delays = Vec::with_capacity(blocks.len());
    // Blocks that repeat a frame (the server writes every ~30 ms whether or not a new frame came)
    // are older than their receipt says: only the first of each frame counts.
    let mut last = f64::NAN;
    for b in blocks {
        if b.frame_t == last {
            continue;
        }
        last = b.frame_t;
        clock.observe(b.frame_t, b.receipt);
        delays.push(b.receipt - b.frame_t);
    }
    StageDelays::of(&delays).map(|s| (s, clock.offset()))
}

/// A sighting of the moving fiducial: when it arrived (host epoch s), its capture time (tracker
/// clock, epoch s) and its position along the motion (m, our frame).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct MarkerSighting {
    pub receipt: f64,
    pub capture: f64,
    pub position: f64,
}

/// The moving fiducial: drawn at `x0 + speed * (t - t0)` (host epoch s). Returns (render to
/// receipt, render to capture): the second is render to photon when the clocks are in step.
pub(crate) fn moving_marker(
    sightings: &[MarkerSighting],
    t0: f64,
    x0: f64,
    speed: f64,
) -> Option<(StageDelays, StageDelays)> {
    if speed.abs() < 1e-6 {
        return None;
    }
    let mut total = Vec::new();
    let mut photon = Vec::new();
    let mut last = f64::NAN;
    for s in sightings {
        if s.capture == last {
            continue;
        }
        last = s.capture;
        let drawn = t0 + (s.position - x0) / speed;
        total.push(s.receipt - drawn);
        photon.push(s.capture - drawn);
    }
    Some((StageDelays::of(&total)?, StageDelays::of(&photon)?))
}

/// Time a robot starting from rest takes to cover `distance` at `speed` behind a first-order motor
/// of time constant `lag`: `speed * (t - lag * (1 - exp(-t / lag))) = distance`.
pub(crate) fn time_to_cover(distance: f64, speed: f64, lag: f64) -> f64 {
    let covered = |t: f64| {
        speed
            * if lag > 0.0 {
                t - lag * (1.0 - (-t / lag).exp())
            } else {
                t
            }
    };
    let (mut lo, mut hi) = (0.0, 10.0);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if covered(mid) < distance {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// Command to motion: the command went out at `sent` (host epoch s); `track` holds (capture time,
/// distance from the start, m). The first capture beyond `threshold`, less the motor model's time to
/// cover it, is when the robot started.
pub(crate) fn command_to_motion(
    sent: f64,
    track: &[(f64, f64)],
    threshold: f64,
    speed: f64,
    motor_lag: f64,
) -> Option<f64> {
    let (t, _) = track.iter().find(|(_, d)| *d >= threshold)?;
    Some(t - time_to_cover(threshold, speed, motor_lag) - sent)
}

/// Every stage measured, and what to set.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct LatencyReport {
    pub date: String,
    pub capture_to_receipt: Option<StageDelays>,
    /// `receipt - frame time` at its fastest, s: the tracker clock's offset plus the fastest
    /// delivery (0.04 for a 40 ms tracker on this machine's clock).
    pub clock_offset: Option<f64>,
    pub render_to_receipt: Option<StageDelays>,
    pub render_to_photon: Option<StageDelays>,
    pub command_to_motion: Option<StageDelays>,
    /// For the scenario's `[tracker] latency` (the simulator's model): capture to receipt, median.
    pub tracker_latency: Option<f64>,
    /// For `[rig] latency` (the compensation): what the live loop's pose ages leave out (the fastest
    /// delivery) plus render to photon.
    pub rig_latency: Option<f64>,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_jittered_delay_gives_its_median_and_fastest() {
        let blocks: Vec<_> = (0..200)
            .map(|k| {
                let t = 1000.0 + k as f64 * 0.033;
                let jitter = ((k * 37) % 21) as f64 / 1000.0 - 0.010;
                BlockTiming {
                    frame_t: t,
                    receipt: t + 0.040 + jitter,
                }
            })
            .collect();
        let (s, offset) = capture_to_receipt(&blocks).unwrap();
        assert!((s.median - 0.040).abs() < 1e-3, "{s:?}");
        assert!((offset - 0.030).abs() < 1e-3, "{offset}");
    }

    #[test]
    fn a_marker_lagging_by_offset_over_speed() {
        let sightings: Vec<_> = (0..50)
            .map(|k| {
                let drawn = 10.0 + k as f64 * 0.02;
                MarkerSighting {
                    receipt: drawn + 0.07,
                    capture: drawn + 0.03,
                    position: 0.2 + 0.25 * (drawn - 10.0),
                }
            })
            .collect();
        let (total, photon) = moving_marker(&sightings, 10.0, 0.2, 0.25).unwrap();
        assert!((total.median - 0.07).abs() < 1e-9 && (photon.median - 0.03).abs() < 1e-9);
    }

    #[test]
    fn motion_onset_behind_a_motor_lag() {
        let (speed, lag, start) = (0.1, 0.05, 5.02);
        let track: Vec<_> = (0..40)
            .map(|k| {
                let t = 5.0 + k as f64 * 0.01;
                let s = (t - start).max(0.0);
                (t, speed * (s - lag * (1.0 - (-s / lag).exp())))
            })
            .collect();
        let d = command_to_motion(5.0, &track, 0.005, speed, lag).unwrap();
        assert!((d - 0.02).abs() < 0.011, "{d}");
    }
}
