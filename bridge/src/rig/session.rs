//! The live loop's edges: poses from the tracker, telemetry from the link, the clock, the watchdog,
//! the screen's sinks, the logs, and the frames out; [`LoopCore`] in the middle. [`super::run`] ticks
//! it at the screen's rate; the Python plants tick it from a policy's `step`.
use super::RigEnds;
use super::core::{LoopCore, PoseIn, TickInput};
use super::gif_thread::GifThread;
use super::options::{FrameRate, LiveOptions, LiveReport};
use super::recorder::{Recorder, Topic, fnv1a};
use super::stopper::{SharedLog, StopOnDrop, Stopper, record};
use super::watchdog::{self, Heartbeats, SafetyLimits, StopReason};
use crate::protocol::colias::Telemetry;
use crate::transport::FrameServer;
use crate::transport::{ClockOffset, epoch_s};
use crate::transport::{ConnectionState, PoseSource};
use colcos_sim::behaviour::WheelCommand;
use colcos_sim::error::{Result, SimError};
use colcos_sim::output::{TickRows, TrajectoryLog};
use colcos_sim::scenario::Scenario;
use image::RgbImage;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

pub struct LiveSession {
    core: LoopCore,
    source: Box<dyn PoseSource>,
    stopper: Stopper,
    beats: Arc<Heartbeats>,
    stops: Arc<Mutex<Vec<String>>>,
    _watchdog: watchdog::WatchdogGuard,
    frames: Option<FrameServer>,
    opts: LiveOptions,
    trajectory: Option<TrajectoryLog>,
    gif: Option<GifThread>,
    next_gif: f64,
    // The frames drawn for the stream and the display, kept: a fresh 4K image costs its page faults
    // (~5 ms) every time.
    stream_img: RgbImage,
    display_img: RgbImage,
    scenario: Scenario,
    groups: Vec<usize>,
    clock: ClockOffset,
    dt: f64,
    period: Duration,
    start: Instant,
    last_tick: Option<Instant>,
    next: Instant,
    last_status: Instant,
    stream_size: (u32, u32),
    next_frame: f64,
    next_display: f64,
    display_gone: bool,
    report: LiveReport,
    tick_ms: Vec<f64>,
    // Reused every tick.
    poses: Vec<PoseIn>,
    telemetry: Vec<Telemetry>,
    stopped: Vec<bool>,
    /// Since when, and why, the link has failed every tick (None: the last pump worked).
    link_failing: Option<(Instant, String)>,
    /// The tracker's problem last told to the operator.
    told_tracker: Option<String>,
    // Last: stops every robot when the session is dropped, after everything above.
    _stop_on_exit: StopOnDrop,
}

impl LiveSession {
    /// A loop over `scenario`'s robots, its watchdog running from now.
    pub fn new(scenario: &Scenario, ends: RigEnds, opts: LiveOptions) -> Result<LiveSession> {
        let RigEnds {
            source,
            link,
            frames,
        } = ends;
        let core = LoopCore::new(scenario, opts.legacy)?;
        let rig = &scenario.spec.rig;
        let n = core.robot_count();
        let recorder = match &opts.log {
            Some(path) => {
                let bad = |e: super::recorder::RecorderError| {
                    SimError::invalid("--log", path.display(), e.to_string())
                };
                let mut rec = Recorder::create(path).map_err(bad)?;
                rec.write_metadata("rig", run_metadata(scenario))
                    .map_err(bad)?;
                Some(rec)
            }
            None => None,
        };
        let trajectory = match &opts.trajectory {
            Some(path) => Some(TrajectoryLog::create(path, &scenario.spec.robots)?),
            None => None,
        };
        let out = &scenario.spec.output;
        let gif = match &opts.gif {
            Some(path) if out.gif_interval > 0.0 => Some(GifThread::start(
                path,
                &scenario.spec.screen,
                out.gif_width,
                out.gif_interval as f64,
            )?),
            _ => None,
        };
        let start = Instant::now();
        let stopper = Stopper {
            link: Arc::new(Mutex::new(link)),
            log: Arc::new(Mutex::new(recorder)),
            radio: core.radio().to_vec(),
            firmware: core.firmware(),
            start,
            warned: Default::default(),
        };
        let beats = Heartbeats::new(n);
        let limits = SafetyLimits {
            tracker_silence: rig.tracker_silence as f64,
            pose_age: rig.pose_age as f64,
            policy_stall: rig.policy_stall as f64,
            ..SafetyLimits::default()
        };
        let stops = Arc::new(Mutex::new(Vec::new()));
        let watchdog = {
            let (stopper, stops) = (stopper.clone(), stops.clone());
            watchdog::spawn(beats.clone(), limits, move |reason| {
                stopper.stop(reason);
                if let Ok(mut s) = stops.lock() {
                    s.push(reason.kind().to_string());
                }
            })
        };
        let dt = scenario.spec.dt as f64;
        let stream_size = FrameRate::size(opts.stream.width, scenario.spec.screen.size);
        Ok(LiveSession {
            groups: core.host().groups(),
            core,
            source,
            _stop_on_exit: StopOnDrop(stopper.clone()),
            stopper,
            beats,
            stops,
            _watchdog: watchdog,
            frames,
            opts,
            trajectory,
            gif,
            next_gif: 0.0,
            stream_img: RgbImage::new(0, 0),
            display_img: RgbImage::new(0, 0),
            scenario: scenario.clone(),
            clock: ClockOffset::default(),
            dt,
            period: Duration::from_secs_f64(dt),
            start,
            last_tick: None,
            next: start,
            last_status: start,
            stream_size,
            next_frame: 0.0,
            next_display: 0.0,
            display_gone: false,
            report: LiveReport {
                rig_latency: rig.latency,
                tracker_latency: scenario.spec.tracker.latency,
                ..LiveReport::default()
            },
            tick_ms: Vec::new(),
            poses: Vec::with_capacity(n),
            telemetry: Vec::new(),
            stopped: vec![false; n],
            link_failing: None,
            told_tracker: None,
        })
    }

    pub fn core(&self) -> &LoopCore {
        &self.core
    }
    pub fn core_mut(&mut self) -> &mut LoopCore {
        &mut self.core
    }
    /// Puts a new core (a new episode's fields and behaviours) on the same tracker, link and logs;
    /// the next tick's fields advance by one period.
    pub fn replace_core(&mut self, core: LoopCore) {
        self.core = core;
        self.last_tick = None;
    }
    /// The core, the rest let go: the robots stopped, the watchdog ended, the logs finished.
    pub fn into_core(self) -> LoopCore {
        self.core
    }
    /// Seconds since the session started.
    pub fn elapsed(&self) -> f64 {
        self.start.elapsed().as_secs_f64()
    }
    /// Stops every robot now (all of them, broadcast) for `why`, ahead of anything queued; the
    /// report's stops list it as `shutdown`.
    pub fn stop_all(&self, why: &str) {
        self.stopper.stop(&StopReason::Shutdown(why.to_string()));
        if let Ok(mut s) = self.stops.lock() {
            s.push("shutdown".into());
        }
    }
    /// Marks in the rig log that episode `episode` starts with the next tick (a replay plays the
    /// recorded episodes one by one).
    pub fn mark_episode(&self, episode: u64) {
        let marker = serde_json::json!({"kind": "episode", "episode": episode, "tick": self.report.ticks + 1});
        record(self.log(), Topic::Events, marker.to_string().as_bytes());
    }
    /// Marks in the rig log that the episode under way ends with the last tick.
    pub fn mark_episode_end(&self) {
        let marker = serde_json::json!({"kind": "episode_end", "tick": self.report.ticks + 1});
        record(self.log(), Topic::Events, marker.to_string().as_bytes());
    }
    /// How long, in s, and why the robot link has failed on every tick; None while it works.
    pub fn link_problem(&self) -> Option<(f64, String)> {
        (self.link_failing.as_ref())
            .map(|(since, why)| (since.elapsed().as_secs_f64(), why.clone()))
    }
    /// Why no pose is arriving from the tracker (its address and the reason); None while poses
    /// arrive.
    pub fn tracker_problem(&self) -> Option<String> {
        self.source.problem()
    }
    fn log(&self) -> &SharedLog {
        &self.stopper.log
    }

    /// One tick now: poses and telemetry in, the core's tick (with `overrides` for a policy's robots,
    /// empty for none), the screen to its sinks, frames out, the logs.
    pub fn tick(&mut self, overrides: &[Option<WheelCommand>]) -> Result<()> {
        let now = Instant::now();
        let t = now.duration_since(self.start).as_secs_f64();
        self.take_poses();
        // Fields, injection, sensing, decisions, on the measured time since the last tick.
        let step = self
            .last_tick
            .map_or(self.dt, |last| now.duration_since(last).as_secs_f64());
        self.last_tick = Some(now);
        match self.exchange(t, step, overrides) {
            // A link that keeps failing is stopped (and said) once, when it starts failing.
            Some(e) if self.link_failing.is_none() => {
                self.stopper.stop(&StopReason::LinkError(e.clone()));
                if let Ok(mut s) = self.stops.lock() {
                    s.push("link_error".into());
                }
                self.link_failing = Some((now, e));
            }
            Some(_) => {}
            None => self.link_failing = None,
        }
        let problem = self.source.problem();
        if let Some(p) = &problem
            && self.told_tracker.as_ref() != Some(p)
        {
            log::warn!("no poses from the tracker at {p}; retrying with backoff");
        }
        if problem.is_some() {
            self.told_tracker = problem;
        }
        self.beats.policy();
        for &i in self.core.fresh() {
            self.beats.pose(i);
        }
        self.report.ticks += 1;
        for e in self.core.take_events() {
            record(self.log(), Topic::Events, e.as_bytes());
        }
        self.show_screen(t);
        // Nothing is drawn or logged before the tracker's first pose: robots are not at (0, 0).
        let tracking = self.report.pose_blocks > 0;
        if let Some(gif) = self.gif.as_mut()
            && tracking
            && t >= self.next_gif
        {
            self.next_gif = t + gif.interval;
            let (w, h) = gif.size;
            let host = self.core.host();
            gif.push(colcos_sim::output::gif::arena_image(
                host,
                &self.scenario.spec.robots,
                w,
                h,
            ));
        }
        if tracking {
            self.write_trajectory()?;
        }
        if let Ok(mut l) = self.log().lock()
            && let Some(r) = l.as_mut()
        {
            let _ = r.flush();
        }
        let work = now.elapsed().as_secs_f64() * 1e3;
        self.tick_ms.push(work);
        if self.opts.status && now.duration_since(self.last_status) >= Duration::from_secs(1) {
            self.last_status = now;
            self.print_status(t, work);
        }
        Ok(())
    }

    /// Telemetry in, the core's tick, the frames out, under the link's lock: a watchdog stop (which
    /// takes the lock) goes out after this tick's frames, never before a motion frame that was decided
    /// without it, and the stops read here are the ones the frames obey. Returns a link error.
    fn exchange(
        &mut self,
        t: f64,
        step: f64,
        overrides: &[Option<WheelCommand>],
    ) -> Option<String> {
        let link = Arc::clone(&self.stopper.link);
        let mut l = link.lock().unwrap_or_else(|e| e.into_inner());
        self.telemetry = l.take_telemetry();
        for tm in &self.telemetry {
            record(&self.stopper.log, Topic::Telemetry, &tm.to_frame());
        }
        let n = self.core.robot_count();
        for (i, s) in self.stopped.iter_mut().enumerate().take(n) {
            *s = self.beats.is_stopped(i);
        }
        self.core.tick(&TickInput {
            t,
            step,
            poses: &self.poses,
            telemetry: &self.telemetry,
            stopped: &self.stopped,
            overrides,
        });
        for packet in self.core.packets() {
            l.send(*packet);
            record(&self.stopper.log, Topic::Commands, &packet.to_frame());
        }
        let error = l.pump().err().map(|e| e.to_string());
        let stopped: Vec<usize> = (self.stopped.iter().enumerate())
            .filter(|(_, s)| **s)
            .map(|(i, _)| i)
            .collect();
        let marker = serde_json::json!({"tick": self.report.ticks + 1, "t": t, "step": step, "stopped": stopped, "commands": self.core.packets().len()});
        record(
            &self.stopper.log,
            Topic::Ticks,
            marker.to_string().as_bytes(),
        );
        error
    }

    /// Waits for the next tick's slot; a tick that ended after its slot is an overrun, and the next
    /// starts at once rather than catching up a backlog.
    pub fn wait_next(&mut self) {
        self.next += self.period;
        let after = Instant::now();
        if after > self.next {
            self.report.overruns += 1;
            self.next = after;
        } else {
            std::thread::sleep(self.next - after);
        }
    }

    /// Whether the options' duration is over.
    pub fn is_over(&self) -> bool {
        self.opts.duration.is_some_and(|d| self.elapsed() >= d)
    }

    fn take_poses(&mut self) {
        self.poses.clear();
        if let Some(snapshot) = self.source.poll() {
            self.report.pose_blocks += 1;
            self.beats.tracker();
            let now_epoch = epoch_s();
            let receipt = now_epoch - snapshot.received.elapsed().as_secs_f64();
            self.clock.observe(snapshot.t, receipt);
            for p in &snapshot.poses {
                self.poses.push(PoseIn {
                    id: p.id,
                    pose: p.pose,
                    age: self.clock.age(p.t, now_epoch),
                    fresh: p.fresh,
                });
            }
            let json: Vec<_> = self.poses.iter().map(|p| serde_json::json!({"id": p.id, "x": p.pose.pos.x, "y": p.pose.pos.y, "heading": p.pose.heading, "age": p.age, "fresh": p.fresh})).collect();
            record(
                self.log(),
                Topic::Poses,
                serde_json::Value::Array(json).to_string().as_bytes(),
            );
        }
        if matches!(
            self.source.state(),
            ConnectionState::Disconnected { .. }
                | ConnectionState::Finished
                | ConnectionState::Failed(_)
        ) || self
            .source
            .take_events()
            .contains(&crate::protocol::swarmcon::TrackerEvent::Closed)
        {
            self.beats.tracker_closed();
        }
    }

    /// The screen to the frame stream and the LCD's window, each at its own rate.
    fn show_screen(&mut self, t: f64) {
        let host = self.core.host();
        if let Some(server) = self.frames.as_mut()
            && self.stream_size.0 > 0
            && t >= self.next_frame
            && server.subscribers() > 0
        {
            self.next_frame = t + if self.opts.stream.hz > 0.0 {
                1.0 / self.opts.stream.hz
            } else {
                0.0
            };
            let img = kept(&mut self.stream_img, self.stream_size.0, self.stream_size.1);
            host.render_into(img);
            server.publish(img, host.time() as f64);
            let json = serde_json::json!({"tick": self.report.ticks, "width": img.width(), "height": img.height(), "fnv1a": format!("{:016x}", fnv1a(img.as_raw()))});
            record(
                &self.stopper.log,
                Topic::Frames,
                json.to_string().as_bytes(),
            );
        }
        if let Some(display) = &self.opts.display
            && !self.display_gone
            && t >= self.next_display
        {
            let frames = self.opts.display_frames;
            self.next_display = t + 1.0 / frames.hz.clamp(1.0, 50.0);
            let (w, h) =
                FrameRate::size(frames.width.clamp(16, 7680), self.scenario.spec.screen.size);
            let img = kept(&mut self.display_img, w, h);
            host.render_into(img);
            if let Ok(mut d) = display.lock()
                && !d.show(img)
            {
                self.display_gone = true;
                log::warn!("the display window was closed; the loop goes on without it");
            }
        }
    }

    fn write_trajectory(&mut self) -> Result<()> {
        if let Some(traj) = self.trajectory.as_mut() {
            let host = self.core.host();
            let lay: Vec<&[f32]> = match traj.has_lay_columns() {
                true => (0..host.poses().len())
                    .map(|i| host.deposit_actions(i))
                    .collect(),
                false => Vec::new(),
            };
            traj.record_rows(&TickRows {
                // Counted from 0 at the first tick with poses, as `colcos run` counts its steps.
                tick: self.report.logged_ticks,
                time: host.time(),
                poses: host.poses(),
                tracked: host.tracked(),
                obs: host.observations(),
                commands: self.core.sent(),
                groups: &self.groups,
                group_specs: &self.scenario.spec.robots,
                lay: &lay,
            })?;
            self.report.logged_ticks += 1;
        }
        Ok(())
    }

    fn print_status(&self, t: f64, work: f64) {
        let host = self.core.host();
        let n = self.core.robot_count();
        // Seen: a pose no older than the watchdog allows, not merely one seen once.
        let max_age = self.scenario.spec.rig.pose_age;
        let seen = (host.tracked().iter())
            .filter(|p| p.seen && host.time() - p.stamp <= max_age)
            .count();
        let counters = self
            .stopper
            .link
            .lock()
            .map(|l| l.counters())
            .unwrap_or_default();
        let age = (host.tracked().iter())
            .filter(|p| p.seen)
            .map(|p| host.time() - p.stamp)
            .fold(0.0f32, f32::max);
        let shield = &self.core.counters().shield;
        eprint!(
            "\r{t:7.1} s  {:5.1} Hz  tick {work:5.2} ms  oldest pose {:4.0} ms  seen {seen}/{n}  sent {}  queued {}  overruns {}  shield {}/{}   ",
            self.report.ticks as f64 / t.max(1e-9),
            age * 1e3,
            counters.scheduler.sent,
            counters.pending,
            self.report.overruns,
            shield.capped,
            shield.walled,
        );
    }

    /// What the session measured so far.
    pub fn report(&self) -> LiveReport {
        let mut report = self.report.clone();
        report.seconds = self.elapsed();
        let mut ms = self.tick_ms.clone();
        ms.sort_by(f64::total_cmp);
        report.worst_tick_ms = ms.last().copied().unwrap_or(0.0);
        let p99 = ((ms.len() as f64 * 0.99) as usize).min(ms.len().saturating_sub(1));
        report.p99_tick_ms = ms.get(p99).copied().unwrap_or(0.0);
        let c = self.core.counters();
        report.shield = c.shield;
        report.commands_sent = c.commands_sent;
        report.telemetry_received = c.telemetry_received;
        report.silent_robots = c.silent_robots.clone();
        report.stops = self.stops.lock().map(|s| s.clone()).unwrap_or_default();
        report.tracker_problem = self.source.problem().or_else(|| self.told_tracker.clone());
        report.link_problem = self.link_failing.as_ref().map(|(_, e)| e.clone());
        report.gif_frames_dropped = self.gif.as_ref().map_or(0, |g| g.dropped);
        if let Ok(l) = self.stopper.link.lock() {
            let c = l.counters().scheduler;
            (report.frames_on_air, report.frames_superseded) = (c.sent, c.superseded);
        }
        report
    }
}

/// `img`, made `width x height` if it is not.
fn kept(img: &mut RgbImage, width: u32, height: u32) -> &mut RgbImage {
    if img.dimensions() != (width, height) {
        *img = RgbImage::new(width, height);
    }
    img
}

/// What a rig log records the run ran with (metadata `rig`): the latencies (s) and calibrations.
fn run_metadata(scenario: &Scenario) -> std::collections::BTreeMap<String, String> {
    let rig = &scenario.spec.rig;
    let none = || "none".to_string();
    [
        // What a replay checks the log against: the scenario it is replayed with.
        ("scenario", scenario.spec.name.clone()),
        ("robots", scenario.robot_count().to_string()),
        ("rig_latency", rig.latency.to_string()),
        ("tracker_latency", scenario.spec.tracker.latency.to_string()),
        (
            "screen_calibration",
            rig.screen_calibration.clone().unwrap_or_else(none),
        ),
        (
            "colour_calibration",
            rig.colour_calibration.clone().unwrap_or_else(none),
        ),
    ]
    .into_iter()
    // Named only where set: a log of a run without it keeps the bytes it had before the key existed.
    .chain(rig.compensate.clone().map(|f| ("compensate", f)))
    .map(|(k, v)| (k.to_string(), v))
    .collect()
}
