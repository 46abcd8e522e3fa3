//! What moves a plant's arena: a live loop against a rig or a twin (paced by the real clock), or a
//! recorded rig run fed tick by tick; and the twin a `plant="twin"` starts in this process when it is
//! given no addresses.
use crate::PlantError;
use colcos_bridge::protocol::colias::LegacyDrive;
use colcos_bridge::protocol::swarmcon::HeaderForm;
use colcos_bridge::rig::HostWorld;
use colcos_bridge::rig::replay::{RecordedTick, feed};
use colcos_bridge::rig::{LiveSession, LoopCore};
use colcos_bridge::twin::{TrackerServer, Twin, UdpChannel};
use colcos_sim::behaviour::WheelCommand;
use colcos_sim::scenario::Scenario;
use colcos_sim::shield::Intervention;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

pub(super) fn closed_error() -> PlantError {
    PlantError::State(
        "this environment was closed (its robots stopped): make a new one to drive them again"
            .into(),
    )
}

pub(crate) enum Driver {
    Live {
        session: Box<LiveSession>,
        /// The URLs its errors name.
        tracker: String,
        robots: String,
        /// Declared after the session: the session stops the robots before the twin goes.
        _twin: Option<TwinThread>,
    },
    Replay {
        core: Box<LoopCore>,
        ticks: Vec<RecordedTick>,
        /// The ticks of each recorded episode, `[first, end)`.
        episodes: Vec<(usize, usize)>,
        /// The next tick, and the end of the episode being replayed.
        next: usize,
        end: usize,
    },
    /// Closed: the last tick's state, kept for reading; nothing can drive from here.
    Closed { core: Box<LoopCore> },
}

/// Longest a reset waits for the tracker to have seen every robot.
pub(crate) const POSE_WAIT_S: f64 = 5.0;
/// Longest a robot link may fail on every tick before a reset or step gives up.
pub(crate) const LINK_FAIL_S: f64 = 1.0;

impl Driver {
    pub fn core(&self) -> &LoopCore {
        match self {
            Driver::Live { session, .. } => session.core(),
            Driver::Replay { core, .. } | Driver::Closed { core } => core,
        }
    }
    pub fn host(&self) -> &HostWorld {
        self.core().host()
    }
    pub fn host_mut(&mut self) -> &mut HostWorld {
        match self {
            Driver::Live { session, .. } => session.core_mut().host_mut(),
            Driver::Replay { core, .. } | Driver::Closed { core } => core.host_mut(),
        }
    }
    pub fn interventions(&self) -> &[Intervention] {
        self.core().interventions()
    }

    /// One tick with `overrides`; a live loop waits for its slot first. False when a replay has no
    /// tick left (nothing happened).
    pub fn tick(&mut self, overrides: &[Option<WheelCommand>]) -> Result<bool, PlantError> {
        match self {
            Driver::Live {
                session, robots, ..
            } => {
                session.wait_next();
                session.tick(overrides)?;
                match session.link_problem() {
                    Some((for_s, why)) if for_s >= LINK_FAIL_S => {
                        Err(PlantError::Unreachable(format!(
                            "the robot link {robots} has failed for {for_s:.1} s ({why}); \
                             the robots were told to stop"
                        )))
                    }
                    _ => Ok(true),
                }
            }
            Driver::Closed { .. } => Err(closed_error()),
            Driver::Replay {
                core,
                ticks,
                next,
                end,
                ..
            } => {
                let Some(tick) = ticks.get(*next).filter(|_| next < end) else {
                    return Ok(false);
                };
                feed(core, tick, overrides);
                *next += 1;
                Ok(true)
            }
        }
    }

    /// Marks in a live plant's rig log that the episode under way ends here (what follows, up to the
    /// next episode, is a reset's go-to drive).
    pub fn mark_end(&self) {
        if let Driver::Live { session, .. } = self {
            session.mark_episode_end();
        }
    }

    /// Ticks left in a replay (None: live).
    pub fn remaining(&self) -> Option<usize> {
        match self {
            Driver::Live { .. } | Driver::Closed { .. } => None,
            Driver::Replay { next, end, .. } => Some(end.saturating_sub(*next)),
        }
    }

    /// A new episode: fresh fields and behaviours (random streams of world index `index`) on the
    /// same link and tracker; a replay plays the log's recorded episode `episode` (counted from the
    /// seed, as the live plant counted them; after the last, the first again).
    pub fn restart(
        &mut self,
        scenario: &Scenario,
        index: u64,
        episode: u64,
    ) -> Result<(), PlantError> {
        let mut core = LoopCore::with_index(scenario, LegacyDrive::default(), index)?;
        match self {
            Driver::Live { session, .. } => {
                core.host_mut().adopt_tracking(session.core().host());
                session.replace_core(core);
                session.mark_episode(episode);
            }
            Driver::Replay {
                core: c,
                episodes,
                next,
                end,
                ..
            } => {
                // The recorded episodes in turn, from the first again after the last.
                let Some(&range) = episodes.get(episode as usize % episodes.len().max(1)) else {
                    return Err(PlantError::State("the rig log holds no episode".into()));
                };
                **c = core;
                (*next, *end) = range;
            }
            Driver::Closed { .. } => return Err(closed_error()),
        }
        Ok(())
    }

    /// Waits, ticking with every robot stopped, until the tracker has seen every robot: an
    /// episode's first observation is never of a pose that was not tracked. Raises naming the URL
    /// and the reason when the tracker or the link cannot be reached.
    pub fn await_poses(&mut self) -> Result<(), PlantError> {
        let Driver::Live { tracker, .. } = self else {
            return Ok(());
        };
        let tracker = tracker.clone();
        let start = std::time::Instant::now();
        let n = self.host().tracked().len();
        let still = vec![Some(WheelCommand::STOP); n];
        loop {
            let unseen: Vec<usize> = (self.host().tracked().iter().enumerate())
                .filter(|(_, p)| !p.seen)
                .map(|(i, _)| i)
                .collect();
            if unseen.is_empty() {
                return Ok(());
            }
            let waited = start.elapsed().as_secs_f64();
            if waited >= POSE_WAIT_S {
                let Driver::Live { session, .. } = &*self else {
                    return Ok(());
                };
                let why = if unseen.len() == n {
                    let reason = session.tracker_problem().unwrap_or_else(|| {
                        "connected, but no frame with these robots arrived".into()
                    });
                    format!("no pose from the tracker {tracker} in {waited:.1} s ({reason})")
                } else {
                    let list: Vec<String> = unseen.iter().map(|i| i.to_string()).collect();
                    format!(
                        "the tracker {tracker} has not seen robot(s) {} of {n} in {waited:.1} s",
                        list.join(", ")
                    )
                };
                return Err(PlantError::Unreachable(format!(
                    "{why}; the robots were told to stop"
                )));
            }
            self.tick(&still)?;
        }
    }

    /// Lets go of the tracker, the link (its guard's stop the last frame sent) and a twin started
    /// here; the last tick's state stays readable.
    pub fn close(&mut self, scenario: &Scenario) -> Result<(), PlantError> {
        let placeholder = LoopCore::new(scenario, LegacyDrive::default())?;
        let old = std::mem::replace(
            self,
            Driver::Closed {
                core: Box::new(placeholder),
            },
        );
        let core = match old {
            // The session (and its guard's final stop) goes before the twin.
            Driver::Live { session, _twin, .. } => session.into_core(),
            Driver::Replay { core, .. } | Driver::Closed { core } => *core,
        };
        *self = Driver::Closed {
            core: Box::new(core),
        };
        Ok(())
    }

    /// Seconds since the plant started (live), or the replay's recorded time.
    pub fn time(&self) -> f64 {
        match self {
            Driver::Live { session, .. } => session.elapsed(),
            Driver::Closed { core } => core.host().time() as f64,
            Driver::Replay { ticks, next, .. } => next
                .checked_sub(1)
                .and_then(|k| ticks.get(k))
                .map_or(0.0, |t| t.t),
        }
    }
}

/// The ticks of each episode a plant recorded (`[first, end)`, from its `episode` and
/// `episode_end` events: a reset's go-to drive lies between two episodes), or, in a log without
/// them, one episode from the first tick with poses to the end.
pub(crate) fn episode_ranges(
    log: &[colcos_bridge::rig::recorder::Recorded],
    ticks: &[RecordedTick],
) -> Vec<(usize, usize)> {
    let at = |tick: u64| {
        ticks
            .iter()
            .position(|t| t.tick >= tick)
            .unwrap_or(ticks.len())
    };
    let events: Vec<(bool, usize)> = (log.iter())
        .filter(|m| m.topic == colcos_bridge::rig::recorder::Topic::Events)
        .filter_map(|m| serde_json::from_slice::<serde_json::Value>(&m.data).ok())
        .filter_map(|v| {
            let start = match v["kind"].as_str()? {
                "episode" => true,
                "episode_end" => false,
                _ => return None,
            };
            Some((start, at(v["tick"].as_u64()?)))
        })
        .collect();
    let mut ranges = Vec::new();
    for (k, &(start, first)) in events.iter().enumerate() {
        if start {
            let end = events[k + 1..].first().map_or(ticks.len(), |&(_, e)| e);
            ranges.push((first, end));
        }
    }
    if ranges.is_empty() {
        let first = ticks.iter().position(|t| !t.poses.is_empty()).unwrap_or(0);
        ranges.push((first, ticks.len()));
    }
    ranges
}

/// A digital twin on loopback, ticking on its own thread until dropped.
pub(crate) struct TwinThread {
    pub tracker_url: String,
    pub robots_url: String,
    stop: Arc<AtomicBool>,
    handle: Option<std::thread::JoinHandle<()>>,
}

impl TwinThread {
    pub fn start(scenario: &Scenario) -> Result<TwinThread, PlantError> {
        Self::start_seeing(scenario, None)
    }

    /// A twin of `scenario`; colour readings from the frame stream at `frames` when given.
    pub fn start_seeing(
        scenario: &Scenario,
        frames: Option<std::net::SocketAddr>,
    ) -> Result<TwinThread, PlantError> {
        let io = |what: &str, e: std::io::Error| {
            PlantError::Io(format!("starting the twin's {what}: {e}"))
        };
        let tracker = TrackerServer::bind("127.0.0.1:0", HeaderForm::Updated)
            .map_err(|e| io("tracker", e))?;
        let channel = UdpChannel::bind("127.0.0.1:0").map_err(|e| io("robot link", e))?;
        let tracker_url = format!("swarmcon://{}", tracker.local_addr());
        let robots_url = format!(
            "udp://{}",
            channel.local_addr().map_err(|e| io("robot link", e))?
        );
        let mut twin = Twin::new(scenario, tracker, Box::new(channel), frames)?;
        let stop = Arc::new(AtomicBool::new(false));
        let s = stop.clone();
        let handle = std::thread::Builder::new()
            .name("colcos-twin".into())
            .spawn(move || twin.run(None, &s))
            .map_err(|e| io("thread", e))?;
        Ok(TwinThread {
            tracker_url,
            robots_url,
            stop,
            handle: Some(handle),
        })
    }
}

impl Drop for TwinThread {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        if let Some(h) = self.handle.take() {
            let _ = h.join();
        }
    }
}

/// A policy from Python drives the robots from the host: a scenario whose robots run their own
/// (`[rig] onboard`) would ignore its actions, so it is refused.
pub(super) fn refuse_onboard(scenario: &Scenario) -> Result<(), PlantError> {
    match &scenario.spec.rig.onboard {
        Some(path) => Err(colcos_sim::error::SimError::invalid(
            "rig.onboard",
            path,
            "the robots would run their own policy and ignore this environment's actions: \
             run an on-board policy with `colcos bridge` (and `colcos twin`)",
        )
        .into()),
        None => Ok(()),
    }
}
