//! The overhead tracker: poses at its own rate, with latency, noise and dropouts.
//!
//! Frames are due at times `k / rate_hz` (k = 0, 1, ...); a frame is captured from the true poses of
//! the first simulation step at or after its due time and stamped with that step's time (so stamp and
//! pose agree; over a run the frame rate is exact, frame to frame it jitters by up to one step), and
//! each frame is delivered `latency` s after its stamp. In a frame every robot gets Gaussian position
//! and heading noise and is missing with probability `dropout`; a missing robot keeps its previous
//! tracked pose. The very first call reports the true poses at once (`seen = true`) so the host has a
//! place to inject from before the first frame arrives. Tracked headings are wrapped to (-pi, pi], as
//! a real tracker reports them.
use crate::rng::SimRng;
use crate::robot::Pose;
use serde::{Deserialize, Serialize};

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct TrackerParams {
    /// Frames per second.
    pub rate_hz: f32,
    /// Delay from capture to delivery, s.
    pub latency: f32,
    /// Position noise standard deviation, m.
    pub position_noise: f32,
    /// Heading noise standard deviation, rad.
    pub heading_noise: f32,
    /// Probability that a robot is missing from a frame.
    pub dropout: f32,
}

impl Default for TrackerParams {
    fn default() -> Self {
        TrackerParams {
            rate_hz: 30.0,
            latency: 0.04,
            position_noise: 0.001,
            heading_noise: 0.02,
            dropout: 0.01,
        }
    }
}

/// A tracked pose as the host sees it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TrackedPose {
    pub pose: Pose,
    /// Capture time of the frame this pose comes from, s.
    pub stamp: f32,
    /// False until the robot has been seen once.
    pub seen: bool,
}

/// Slack when comparing frame times with the simulation clock, s (absorbs f32 rounding of `t`).
const TIME_EPS: f64 = 1e-5;

/// One captured frame on its way to the host.
struct Frame {
    stamp: f64,
    deliver_at: f64,
    /// Per robot: the noisy pose, or `None` if it dropped out of this frame.
    poses: Vec<Option<Pose>>,
}

pub struct Tracker {
    pub params: TrackerParams,
    tracked: Vec<TrackedPose>,
    /// Frames captured but not yet delivered, oldest first.
    queue: std::collections::VecDeque<Frame>,
    /// Buffers of delivered frames, reused.
    spare: Vec<Vec<Option<Pose>>>,
    /// Index of the next frame to capture.
    next_frame: u64,
    /// Capture time of the newest delivered frame (the first call's time before any arrives).
    latest_stamp: Option<f32>,
    started: bool,
}

impl Tracker {
    pub fn new(params: TrackerParams, robots: usize) -> Self {
        Tracker {
            params,
            tracked: vec![TrackedPose::default(); robots],
            queue: Default::default(),
            spare: Vec::new(),
            next_frame: 0,
            latest_stamp: None,
            started: false,
        }
    }

    /// The latest delivered tracked poses.
    pub fn tracked(&self) -> &[TrackedPose] {
        &self.tracked
    }

    /// Capture time of the newest delivered frame, s; `None` before the first `update`.
    pub fn latest_frame_stamp(&self) -> Option<f32> {
        self.latest_stamp
    }

    /// Whether robot `i`'s tracked pose comes from the newest delivered frame (false when it dropped
    /// out of that frame and keeps an older pose).
    pub fn in_latest_frame(&self, i: usize) -> bool {
        self.tracked
            .get(i)
            .is_some_and(|t| t.seen && Some(t.stamp) == self.latest_stamp)
    }

    /// Forgets everything: the next `update` reports the true poses again, as the first did.
    pub fn reset(&mut self) {
        while let Some(f) = self.queue.pop_front() {
            self.spare.push(f.poses);
        }
        self.next_frame = 0;
        self.latest_stamp = None;
        self.started = false;
        for p in &mut self.tracked {
            *p = TrackedPose::default();
        }
    }

    /// Capture time of frame `k`, s.
    fn frame_time(&self, k: u64) -> f64 {
        k as f64 / self.params.rate_hz as f64
    }

    /// Records the true poses at time `t` and returns the latest delivered tracked poses (a robot that
    /// dropped out keeps its last tracked pose).
    pub fn update(&mut self, t: f32, true_poses: &[Pose], rng: &mut SimRng) -> &[TrackedPose] {
        use rand::RngExt;
        let n = true_poses.len();
        self.tracked.resize(n, TrackedPose::default());
        let now = t as f64;
        let rate_ok = self.params.rate_hz.is_finite() && self.params.rate_hz > 0.0;
        if !self.started {
            self.started = true;
            self.latest_stamp = Some(t);
            for (tp, p) in self.tracked.iter_mut().zip(true_poses) {
                *tp = TrackedPose {
                    pose: *p,
                    stamp: t,
                    seen: true,
                };
            }
            // First frame: the first capture time at or after now.
            self.next_frame = if rate_ok {
                ((now - TIME_EPS) * self.params.rate_hz as f64)
                    .ceil()
                    .max(0.0) as u64
            } else {
                0
            };
        }
        if rate_ok {
            let latency = self.params.latency.max(0.0) as f64;
            let (pos_sd, head_sd) = (
                self.params.position_noise.max(0.0),
                self.params.heading_noise.max(0.0),
            );
            let dropout = self.params.dropout;
            while self.frame_time(self.next_frame) <= now + TIME_EPS {
                // The frame shows the poses of this step, so it is stamped with this step's time.
                let stamp = now;
                self.next_frame += 1;
                let mut poses = self.spare.pop().unwrap_or_default();
                poses.clear();
                for p in true_poses {
                    let dropped = dropout > 0.0 && rng.random::<f32>() < dropout;
                    if dropped {
                        poses.push(None);
                        continue;
                    }
                    let mut q = *p;
                    if pos_sd > 0.0 {
                        q.pos.x += pos_sd * crate::rng::normal(rng);
                        q.pos.y += pos_sd * crate::rng::normal(rng);
                    }
                    if head_sd > 0.0 {
                        q.heading =
                            crate::angle::wrap_pi(q.heading + head_sd * crate::rng::normal(rng));
                    }
                    poses.push(Some(q));
                }
                self.queue.push_back(Frame {
                    stamp,
                    deliver_at: stamp + latency,
                    poses,
                });
            }
        }
        while self
            .queue
            .front()
            .is_some_and(|f| f.deliver_at <= now + TIME_EPS)
        {
            let Some(frame) = self.queue.pop_front() else {
                break;
            };
            self.latest_stamp = Some(frame.stamp as f32);
            for (tp, p) in self.tracked.iter_mut().zip(&frame.poses) {
                if let Some(p) = p {
                    *tp = TrackedPose {
                        pose: *p,
                        stamp: frame.stamp as f32,
                        seen: true,
                    };
                }
            }
            self.spare.push(frame.poses);
        }
        &self.tracked
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f32::consts::PI;

    fn params(dropout: f32, heading_noise: f32) -> TrackerParams {
        TrackerParams {
            rate_hz: 50.0,
            latency: 0.0,
            position_noise: 0.0,
            heading_noise,
            dropout,
        }
    }

    #[test]
    fn robots_missing_from_the_newest_frame_are_told_apart() {
        let mut t = Tracker::new(params(0.5, 0.0), 8);
        let mut r = crate::rng::stream(3, 0, 0);
        let truth = vec![Pose::new(0.5, 0.5, 0.0); 8];
        let (mut fresh, mut missing) = (0, 0);
        for k in 0..200 {
            let time = k as f32 * 0.02;
            t.update(time, &truth, &mut r);
            let latest = t.latest_frame_stamp().unwrap();
            assert!((latest - time).abs() < 1e-6, "frame of {time} delivered");
            for i in 0..8 {
                let stamp = t.tracked()[i].stamp;
                if t.in_latest_frame(i) {
                    assert_eq!(stamp, latest);
                    fresh += 1;
                } else {
                    assert!(stamp < latest, "robot {i}: {stamp} vs {latest}");
                    missing += 1;
                }
            }
        }
        // About half of each: dropout 0.5 (the first step reports every robot).
        assert!((600..1000).contains(&missing), "{missing} missing");
        assert!((600..1000).contains(&fresh), "{fresh} fresh");
        let mut quiet = Tracker::new(params(0.0, 0.0), 3);
        for k in 0..20 {
            quiet.update(k as f32 * 0.02, &truth[..3], &mut r);
            assert!((0..3).all(|i| quiet.in_latest_frame(i)));
        }
    }

    #[test]
    fn noisy_headings_near_pi_stay_in_the_half_open_range() {
        let mut t = Tracker::new(params(0.0, 0.3), 4);
        let mut r = crate::rng::stream(5, 0, 0);
        let truth = [
            Pose::new(0.5, 0.5, PI),
            Pose::new(0.5, 0.5, -PI + 1e-3),
            Pose::new(0.5, 0.5, PI - 1e-3),
            Pose::new(0.5, 0.5, 0.0),
        ];
        let mut crossed = 0;
        for k in 0..300 {
            for (i, p) in t.update(k as f32 * 0.02, &truth, &mut r).iter().enumerate() {
                let h = p.pose.heading;
                assert!(h > -PI && h <= PI, "heading {h}");
                // Robots 0 and 2 head at about +pi: noise past it comes back near -pi.
                crossed += usize::from(i != 1 && i != 3 && h < 0.0);
            }
        }
        assert!(
            crossed > 100,
            "noise carried headings across pi {crossed} times"
        );
    }
}
