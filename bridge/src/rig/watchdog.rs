//! The safety watchdog: a thread apart from the loop that stops the robots when the loop can no
//! longer be trusted to: tracker silence or a closed tracker socket (all robots), a robot with no fresh
//! pose (that robot), a policy that has not stepped, a link error, a shutdown signal. It reads
//! heartbeats the loop writes into atomics, so a loop that hangs (a blocked policy) is still caught.
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::{Duration, Instant};

/// Time limits of the watchdog.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct SafetyLimits {
    /// Longest tracker silence before every robot is stopped, s (100 ms by default).
    pub tracker_silence: f64,
    /// Longest time a robot may go without a fresh pose before it is stopped, s.
    pub pose_age: f64,
    /// Longest time between two policy steps before every robot is stopped, s.
    pub policy_stall: f64,
    /// How often the watchdog looks, s.
    pub period: f64,
}

impl Default for SafetyLimits {
    fn default() -> Self {
        SafetyLimits {
            tracker_silence: 0.1,
            pose_age: 0.3,
            policy_stall: 0.2,
            period: 0.005,
        }
    }
}

/// Why robots were stopped.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum StopReason {
    TrackerSilent { for_s: f64 },
    TrackerClosed,
    PoseStale { robot: usize, age_s: f64 },
    PolicyStalled { for_s: f64 },
    LinkError(String),
    Shutdown(String),
}

impl StopReason {
    /// The robot this concerns, or `None` for all of them.
    pub(crate) fn robot(&self) -> Option<usize> {
        match self {
            StopReason::PoseStale { robot, .. } => Some(*robot),
            _ => None,
        }
    }
    pub(crate) fn kind(&self) -> &'static str {
        match self {
            StopReason::TrackerSilent { .. } => "tracker_silent",
            StopReason::TrackerClosed => "tracker_closed",
            StopReason::PoseStale { .. } => "pose_stale",
            StopReason::PolicyStalled { .. } => "policy_stalled",
            StopReason::LinkError(_) => "link_error",
            StopReason::Shutdown(_) => "shutdown",
        }
    }
}

/// A plain sentence for the operator (the log's `detail` keeps it too).
impl std::fmt::Display for StopReason {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            StopReason::TrackerSilent { for_s } => {
                write!(f, "no pose from the tracker for {for_s:.2} s")
            }
            StopReason::TrackerClosed => write!(f, "the tracker closed its stream"),
            StopReason::PoseStale { robot, age_s } => {
                write!(f, "robot {robot}'s newest pose is {age_s:.2} s old")
            }
            StopReason::PolicyStalled { for_s } => {
                write!(f, "no command from the policy for {for_s:.2} s")
            }
            StopReason::LinkError(e) => write!(f, "{e}"),
            StopReason::Shutdown(why) => write!(f, "{why}"),
        }
    }
}

/// What the loop tells the watchdog, lock-free: microseconds since the watchdog's start (0: never).
pub(crate) struct Heartbeats {
    start: Instant,
    tracker: AtomicU64,
    policy: AtomicU64,
    tracker_closed: AtomicBool,
    /// Per robot: the last fresh pose (0: never seen, not watched).
    poses: Vec<AtomicU64>,
    /// Per robot: stopped by the watchdog and not yet released by a fresh pose.
    stopped: Vec<AtomicBool>,
    all_stopped: AtomicBool,
}

impl Heartbeats {
    pub(crate) fn new(robots: usize) -> Arc<Heartbeats> {
        Arc::new(Heartbeats {
            start: Instant::now(),
            tracker: AtomicU64::new(0),
            policy: AtomicU64::new(0),
            tracker_closed: AtomicBool::new(false),
            poses: (0..robots).map(|_| AtomicU64::new(0)).collect(),
            stopped: (0..robots).map(|_| AtomicBool::new(false)).collect(),
            all_stopped: AtomicBool::new(false),
        })
    }
    fn now_us(&self) -> u64 {
        (self.start.elapsed().as_micros() as u64).max(1)
    }
    /// A tracker block arrived.
    pub(crate) fn tracker(&self) {
        self.tracker.store(self.now_us(), Ordering::Relaxed);
        self.tracker_closed.store(false, Ordering::Relaxed);
    }
    /// The tracker's connection closed.
    pub(crate) fn tracker_closed(&self) {
        self.tracker_closed.store(true, Ordering::Relaxed);
    }
    /// The policy stepped.
    pub(crate) fn policy(&self) {
        self.policy.store(self.now_us(), Ordering::Relaxed);
    }
    /// Robot `i` has a fresh pose.
    pub(crate) fn pose(&self, i: usize) {
        if let Some(p) = self.poses.get(i) {
            p.store(self.now_us(), Ordering::Relaxed);
        }
    }
    /// True while robot `i` (or every robot) is held stopped: the loop must not send it motion.
    pub(crate) fn is_stopped(&self, i: usize) -> bool {
        self.all_stopped.load(Ordering::Relaxed)
            || self
                .stopped
                .get(i)
                .is_some_and(|s| s.load(Ordering::Relaxed))
    }
}

/// The conditions that hold now, each reported once when it starts holding (a condition that clears
/// and holds again is reported again).
pub(crate) fn check(beats: &Heartbeats, limits: &SafetyLimits) -> Vec<StopReason> {
    let now = beats.now_us();
    let age = |t: u64| (now.saturating_sub(t)) as f64 * 1e-6;
    let mut out = Vec::new();
    let tracker = beats.tracker.load(Ordering::Relaxed);
    let policy = beats.policy.load(Ordering::Relaxed);
    let all = if beats.tracker_closed.load(Ordering::Relaxed) {
        Some(StopReason::TrackerClosed)
    } else if tracker != 0 && age(tracker) > limits.tracker_silence {
        Some(StopReason::TrackerSilent {
            for_s: age(tracker),
        })
    } else if policy != 0 && age(policy) > limits.policy_stall {
        Some(StopReason::PolicyStalled { for_s: age(policy) })
    } else {
        None
    };
    let was_all = beats.all_stopped.swap(all.is_some(), Ordering::Relaxed);
    if let Some(reason) = all
        && !was_all
    {
        out.push(reason);
    }
    for (i, (p, s)) in beats.poses.iter().zip(&beats.stopped).enumerate() {
        let t = p.load(Ordering::Relaxed);
        let stale = t != 0 && age(t) > limits.pose_age;
        if stale && !s.swap(true, Ordering::Relaxed) {
            out.push(StopReason::PoseStale {
                robot: i,
                age_s: age(t),
            });
        } else if !stale {
            s.store(false, Ordering::Relaxed);
        }
    }
    out
}

/// Runs [`check`] every `limits.period` on its own thread, calling `on_stop` for each condition as it
/// starts to hold, until the returned guard is dropped.
pub(crate) fn spawn(
    beats: Arc<Heartbeats>,
    limits: SafetyLimits,
    mut on_stop: impl FnMut(&StopReason) + Send + 'static,
) -> WatchdogGuard {
    let stop = Arc::new(AtomicBool::new(false));
    let s = stop.clone();
    let handle = std::thread::Builder::new()
        .name("watchdog".into())
        .spawn(move || {
            let period = Duration::from_secs_f64(limits.period.clamp(0.001, 0.05));
            while !s.load(Ordering::Relaxed) {
                for reason in check(&beats, &limits) {
                    on_stop(&reason);
                }
                std::thread::sleep(period);
            }
        })
        .ok();
    WatchdogGuard { stop, handle }
}

/// Stops the watchdog thread when dropped.
pub(crate) struct WatchdogGuard {
    stop: Arc<AtomicBool>,
    handle: Option<std::thread::JoinHandle<()>>,
}

impl Drop for WatchdogGuard {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        if let Some(h) = self.handle.take() {
            let _ = h.join();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn limits() -> SafetyLimits {
        SafetyLimits {
            tracker_silence: 0.03,
            pose_age: 0.05,
            policy_stall: 0.04,
            period: 0.002,
        }
    }

    #[test]
    fn nothing_is_reported_before_the_first_heartbeats() {
        let beats = Heartbeats::new(3);
        std::thread::sleep(Duration::from_millis(60));
        assert!(check(&beats, &limits()).is_empty());
    }

    #[test]
    fn silence_stale_poses_and_a_stalled_policy_are_reported_once_each() {
        let beats = Heartbeats::new(2);
        beats.tracker();
        beats.policy();
        beats.pose(0);
        beats.pose(1);
        assert!(check(&beats, &limits()).is_empty());
        std::thread::sleep(Duration::from_millis(45));
        beats.tracker();
        beats.pose(1);
        let got = check(&beats, &limits());
        assert_eq!(got.len(), 1, "{got:?}");
        assert_eq!(got[0].kind(), "policy_stalled");
        assert!(beats.is_stopped(0) && beats.is_stopped(1));
        std::thread::sleep(Duration::from_millis(20));
        beats.tracker();
        beats.policy();
        beats.pose(1);
        let got = check(&beats, &limits());
        assert_eq!(got.len(), 1, "{got:?}");
        assert!(
            matches!(got[0], StopReason::PoseStale { robot: 0, .. }),
            "{got:?}"
        );
        assert!(beats.is_stopped(0) && !beats.is_stopped(1));
        assert!(check(&beats, &limits()).is_empty(), "reported again");
        beats.pose(0);
        assert!(check(&beats, &limits()).is_empty());
        assert!(!beats.is_stopped(0));
        beats.tracker_closed();
        assert_eq!(check(&beats, &limits()), vec![StopReason::TrackerClosed]);
    }

    #[test]
    fn the_thread_reports_tracker_silence_within_its_period() {
        let beats = Heartbeats::new(1);
        let (tx, rx) = std::sync::mpsc::channel();
        let guard = spawn(beats.clone(), limits(), move |r| {
            let _ = tx.send((r.kind(), Instant::now()));
        });
        beats.tracker();
        let t0 = Instant::now();
        let (kind, at) = rx.recv_timeout(Duration::from_secs(2)).unwrap();
        assert_eq!(kind, "tracker_silent");
        let waited = at.duration_since(t0).as_secs_f64();
        assert!((0.03..0.03 + 0.02).contains(&waited), "{waited}");
        drop(guard);
    }
}
