//! The state a source's background thread shares with the live loop, and the one [`PoseSource`]
//! implementation over it.

use super::{ConnectionState, MarkerPose, PoseSnapshot, PoseSource, SourceCounters, SourceError};
use crate::protocol::swarmcon::{Calibrate, TrackerEvent};
use std::collections::VecDeque;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, MutexGuard};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// Events kept for the live loop; older ones are dropped if it never reads them.
const MAX_EVENTS: usize = 64;

#[derive(Debug)]
pub(crate) struct State {
    pub latest: Option<PoseSnapshot>,
    pub state: ConnectionState,
    pub counters: SourceCounters,
    pub events: VecDeque<TrackerEvent>,
    /// A command line waiting to be written to the server.
    pub outgoing: Option<String>,
    /// Why no pose is arriving (the last failure), until the next frame arrives.
    pub problem: Option<String>,
}

/// The thread's handle on the shared state.
#[derive(Clone)]
pub(crate) struct Shared {
    state: Arc<Mutex<State>>,
    stop: Arc<AtomicBool>,
}

impl Shared {
    pub(crate) fn new() -> Self {
        Shared {
            state: Arc::new(Mutex::new(State {
                latest: None,
                state: ConnectionState::Connecting,
                counters: SourceCounters::default(),
                events: VecDeque::new(),
                outgoing: None,
                problem: None,
            })),
            stop: Arc::new(AtomicBool::new(false)),
        }
    }

    /// The lock, even if a thread panicked while holding it (the data stay usable).
    pub(crate) fn lock(&self) -> MutexGuard<'_, State> {
        self.state.lock().unwrap_or_else(|e| e.into_inner())
    }

    pub(crate) fn stopped(&self) -> bool {
        self.stop.load(Ordering::Relaxed)
    }

    pub(crate) fn set_state(&self, s: ConnectionState) {
        let mut g = self.lock();
        match &s {
            ConnectionState::Disconnected { reason, .. } => g.problem = Some(reason.clone()),
            ConnectionState::Failed(reason) => g.problem = Some(reason.clone()),
            _ => {}
        }
        g.state = s;
    }

    pub(crate) fn publish(&self, t: f64, poses: Vec<MarkerPose>) {
        let mut g = self.lock();
        let seq = g.latest.as_ref().map_or(1, |s| s.seq + 1);
        g.latest = Some(PoseSnapshot {
            seq,
            t,
            received: Instant::now(),
            poses,
        });
        g.counters.frames += 1;
        g.problem = None;
    }

    pub(crate) fn event(&self, e: TrackerEvent) {
        let mut g = self.lock();
        if g.events.len() >= MAX_EVENTS {
            g.events.pop_front();
        }
        g.events.push_back(e);
    }

    /// Sleeps up to `d`, waking early when asked to stop; returns false if stopped.
    pub(crate) fn sleep(&self, d: Duration) -> bool {
        let end = Instant::now() + d;
        while !self.stopped() {
            let now = Instant::now();
            if now >= end {
                return true;
            }
            std::thread::sleep((end - now).min(Duration::from_millis(10)));
        }
        false
    }
}

/// A pose source run by a background thread; dropping it stops and joins the thread.
pub(crate) struct ThreadedSource {
    shared: Shared,
    handle: Option<JoinHandle<()>>,
    last_seq: u64,
    can_calibrate: bool,
}

impl ThreadedSource {
    pub(crate) fn spawn(
        shared: Shared,
        can_calibrate: bool,
        body: impl FnOnce(Shared) + Send + 'static,
    ) -> Self {
        let s = shared.clone();
        let handle = std::thread::spawn(move || body(s));
        ThreadedSource {
            shared,
            handle: Some(handle),
            last_seq: 0,
            can_calibrate,
        }
    }
}

impl Drop for ThreadedSource {
    fn drop(&mut self) {
        self.shared.stop.store(true, Ordering::Relaxed);
        if let Some(h) = self.handle.take() {
            let _ = h.join();
        }
    }
}

impl PoseSource for ThreadedSource {
    fn poll(&mut self) -> Option<PoseSnapshot> {
        let g = self.shared.lock();
        let snap = g.latest.as_ref().filter(|s| s.seq > self.last_seq)?.clone();
        drop(g);
        self.last_seq = snap.seq;
        Some(snap)
    }

    fn latest(&self) -> Option<PoseSnapshot> {
        self.shared.lock().latest.clone()
    }

    fn state(&self) -> ConnectionState {
        self.shared.lock().state.clone()
    }

    fn counters(&self) -> SourceCounters {
        self.shared.lock().counters
    }

    fn problem(&self) -> Option<String> {
        self.shared.lock().problem.clone()
    }

    fn take_events(&mut self) -> Vec<TrackerEvent> {
        self.shared.lock().events.drain(..).collect()
    }

    fn request_calibration(&mut self, cmd: &Calibrate) -> Result<(), SourceError> {
        if !self.can_calibrate {
            return Err(SourceError::NoCalibration);
        }
        let line = cmd.encode()?;
        self.shared.lock().outgoing = Some(line);
        Ok(())
    }
}
