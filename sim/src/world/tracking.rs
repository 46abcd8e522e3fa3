//! Tracking: the tracker model (rate, latency, noise, dropouts), its random stream, and the poses it
//! last delivered. Stage `track`.
use crate::rng::SimRng;
use crate::robot::Pose;
use crate::tracker::{TrackedPose, Tracker};

pub struct Tracking {
    tracker: Tracker,
    rng: SimRng,
    tracked: Vec<TrackedPose>,
}

impl Tracking {
    /// A tracker that has seen `poses` at time 0.
    pub fn new(mut tracker: Tracker, mut rng: SimRng, poses: &[Pose]) -> Self {
        let tracked = tracker.update(0.0, poses, &mut rng).to_vec();
        Tracking {
            tracker,
            rng,
            tracked,
        }
    }
    /// Starts over from `poses` at `time`, as a tracker just switched on (robots placed by hand).
    pub fn restart(&mut self, time: f32, poses: &[Pose]) {
        self.tracker.reset();
        let tracked = self.tracker.update(time, poses, &mut self.rng);
        self.tracked.copy_from_slice(tracked);
    }
    /// Poses as the tracker last delivered them.
    pub fn tracked(&self) -> &[TrackedPose] {
        &self.tracked
    }
    /// Capture time of the newest delivered frame (see [`Tracker::latest_frame_stamp`]).
    pub fn latest_frame_stamp(&self) -> Option<f32> {
        self.tracker.latest_frame_stamp()
    }
}

/// Stage `track`: the tracker's view at `time` of the true `poses`.
///
/// Reads `poses`; writes the tracker's state, its random stream and the tracked poses.
pub fn track(tracking: &mut Tracking, time: f32, poses: &[Pose]) {
    let tracked = tracking.tracker.update(time, poses, &mut tracking.rng);
    tracking.tracked.copy_from_slice(tracked);
}
