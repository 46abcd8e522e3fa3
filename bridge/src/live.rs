//! The live loop: at the screen's 20 ms, the latest poses -> injection at the tracked poses (latency
//! compensated) -> field step -> screen -> the display sinks -> observations -> behaviours -> the
//! shield -> wheel commands -> the link. A watchdog thread beside it stops the robots when the loop
//! cannot be trusted to, and a guard stops them whichever way the loop ends.
use crate::clock::{ClockOffset, epoch_ns, epoch_s};
use crate::colias::{
    BROADCAST_ID, CommandPacket, HostCommand, LegacyDrive, MotionKind, colour_to_sim,
};
use crate::frames::FrameServer;
use crate::host::Host;
use crate::recorder::{Recorder, Topic, fnv1a};
use crate::twin::bumper_reading;
use crate::watchdog::{self, Heartbeats, SafetyLimits, StopReason};
use crate::{ConnectionState, PoseSource, RobotLink};
use colcos_sim::behaviour::WheelCommand;
use colcos_sim::error::{Result, SimError};
use colcos_sim::output::{TickRows, TrajectoryLog};
use colcos_sim::scenario::{Firmware, Scenario};
use colcos_sim::shield::{Shield, ShieldCounts};
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// A screen the loop shows its frames on: the window on the arena's LCD.
pub trait FrameSink: Send {
    /// Shows `frame` (row 0 at the top of the panel); false once the sink is gone (window closed).
    fn show(&mut self, frame: &image::RgbImage) -> bool;
}

/// What a live run does besides driving the robots.
#[derive(Default)]
pub struct LiveOptions {
    /// The LCD's window, shown `display_width` px wide at `display_hz` (the window scales it to the
    /// panel). The CPU renders a 4K frame in ~90 ms, so the default is a smaller frame.
    pub display: Option<std::sync::Mutex<Box<dyn FrameSink>>>,
    pub display_width: u32,
    pub display_hz: f64,
    /// Stop after this many seconds (None: until stopped).
    pub duration: Option<f64>,
    /// Width of the frames sent to the frame stream (height from the panel's aspect); 0: none.
    pub stream_width: u32,
    /// Frames sent to the frame stream per second (at most one a tick; 0: every tick). Rendering
    /// costs the loop: a 960-pixel frame of two Gaussian fields takes ~10 ms on one core.
    pub stream_hz: f64,
    /// Where the rig log (MCAP) goes; None: no log.
    pub log: Option<PathBuf>,
    /// Where the trajectory CSV goes (the simulator's columns, the tracked poses as used); None: none.
    pub trajectory: Option<PathBuf>,
    /// Print a status line every second.
    pub status: bool,
    /// How wheel speeds become motion commands for old firmware (`[rig] firmware = "motion"`).
    pub legacy: LegacyDrive,
}

/// What a finished live run measured.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct LiveReport {
    pub ticks: u64,
    pub seconds: f64,
    /// Ticks that ended after their slot.
    pub overruns: u64,
    /// Worst and 99th-percentile time of the loop's own work in a tick, ms.
    pub worst_tick_ms: f64,
    pub p99_tick_ms: f64,
    pub shield: ShieldCounts,
    /// Safety stops the watchdog sent, by kind, in order.
    pub stops: Vec<String>,
    pub commands_sent: u64,
    pub telemetry_received: u64,
    /// Robots (radio addresses) that stopped answering data requests, in the order they fell silent.
    pub silent_robots: Vec<u8>,
    /// Tracker blocks taken.
    pub pose_blocks: u64,
}

type SharedLink = Arc<Mutex<Box<dyn RobotLink>>>;
type SharedLog = Arc<Mutex<Option<Recorder>>>;

fn record(log: &SharedLog, topic: Topic, data: &[u8]) {
    if let Ok(mut l) = log.lock()
        && let Some(r) = l.as_mut()
    {
        let _ = r.record(topic, epoch_ns(), data);
    }
}

/// Milliseconds since `start`, as the host stamps its command frames (wrapping at 2^32).
fn t_ms(start: Instant) -> u32 {
    start.elapsed().as_millis() as u32
}

/// The command that drives robot `id` with `cmd` on firmware `firmware`.
fn drive_packet(
    id: u8,
    t: u32,
    cmd: WheelCommand,
    firmware: Firmware,
    legacy: &LegacyDrive,
) -> CommandPacket {
    let command = match firmware {
        Firmware::Wheels => HostCommand::WheelSpeeds {
            left: cmd.left,
            right: cmd.right,
        },
        Firmware::Motion => legacy.map(cmd),
    };
    CommandPacket::new(id, t, command)
}

/// The command that stops robot `id` (or all of them, [`BROADCAST_ID`]) at once.
fn stop_packet(id: u8, t: u32, firmware: Firmware) -> CommandPacket {
    let command = match firmware {
        Firmware::Wheels => HostCommand::WheelSpeeds {
            left: 0.0,
            right: 0.0,
        },
        Firmware::Motion => HostCommand::Motion {
            kind: MotionKind::Stop,
            speed: 0.0,
        },
    };
    CommandPacket::new(id, t, command)
}

/// What the watchdog and the exit guard need to stop robots.
#[derive(Clone)]
struct Stopper {
    link: SharedLink,
    log: SharedLog,
    radio: Vec<u8>,
    firmware: Firmware,
    start: Instant,
}

impl Stopper {
    /// Sends the stop `reason` calls for, ahead of anything queued, and logs it.
    fn stop(&self, reason: &StopReason) {
        let id = match reason.robot() {
            None => BROADCAST_ID,
            Some(i) => self.radio.get(i).copied().unwrap_or(BROADCAST_ID),
        };
        let packet = stop_packet(id, t_ms(self.start), self.firmware);
        let sent = match self.link.lock() {
            Ok(mut link) => link.stop_now(packet).map_err(|e| e.to_string()),
            Err(_) => Err("link lock poisoned".to_string()),
        };
        if sent.is_ok() {
            record(&self.log, Topic::Commands, &packet.to_frame());
        }
        let event = serde_json::json!({
            "kind": reason.kind(),
            "robot": reason.robot(),
            "detail": format!("{reason:?}"),
            "sent": sent.is_ok(),
        });
        record(&self.log, Topic::Events, event.to_string().as_bytes());
        log::warn!(
            "safety stop ({}): {reason:?}",
            if id == BROADCAST_ID {
                "all robots".to_string()
            } else {
                format!("radio {id}")
            }
        );
    }
}

/// Stops every robot when dropped: the loop's last word, also when it unwinds from a panic.
struct StopOnDrop(Stopper);

impl Drop for StopOnDrop {
    fn drop(&mut self) {
        self.0
            .stop(&StopReason::Shutdown("the live loop ended".into()));
        if let Ok(mut l) = self.0.log.lock()
            && let Some(r) = l.take()
        {
            let _ = r.finish();
        }
    }
}

/// Runs the live loop on `scenario`'s robots until `stop` is set or the duration is over.
pub fn run(
    scenario: &Scenario,
    mut source: Box<dyn PoseSource>,
    link: Box<dyn RobotLink>,
    mut frames: Option<FrameServer>,
    opts: &LiveOptions,
    stop: Arc<AtomicBool>,
) -> Result<LiveReport> {
    let rig = scenario.spec.rig.clone();
    let mut host = Host::new(scenario, rig.sensors)?;
    host.set_latency(rig.latency);
    let n = host.robot_count();
    let radio = rig.radio_addresses(n)?;
    let tracker_ids: Vec<i32> = (0..n).map(|i| rig.tracker_id(i)).collect();
    let shield = Shield::new(rig.shield, scenario.arena_size());
    let recorder = match &opts.log {
        Some(path) => Some(
            Recorder::create(path)
                .map_err(|e| SimError::invalid("--log", path.display(), e.to_string()))?,
        ),
        None => None,
    };
    let mut trajectory = match &opts.trajectory {
        Some(path) => Some(TrajectoryLog::create(path)?),
        None => None,
    };
    let groups = host.groups();
    let start = Instant::now();
    let stopper = Stopper {
        link: Arc::new(Mutex::new(link)),
        log: Arc::new(Mutex::new(recorder)),
        radio: radio.clone(),
        firmware: rig.firmware,
        start,
    };
    let beats = Heartbeats::new(n);
    let limits = SafetyLimits {
        tracker_silence: rig.tracker_silence as f64,
        pose_age: rig.pose_age as f64,
        policy_stall: rig.policy_stall as f64,
        ..SafetyLimits::default()
    };
    let stops = Arc::new(Mutex::new(Vec::new()));
    let _watchdog = {
        let (stopper, stops) = (stopper.clone(), stops.clone());
        watchdog::spawn(beats.clone(), limits, move |reason| {
            stopper.stop(reason);
            if let Ok(mut s) = stops.lock() {
                s.push(reason.kind().to_string());
            }
        })
    };
    let _stop_on_exit = StopOnDrop(stopper.clone());
    let (link, log) = (&stopper.link, &stopper.log);

    let dt = scenario.spec.dt as f64;
    let period = Duration::from_secs_f64(dt);
    let keepalive = 1.0 / rig.keepalive_hz.max(1.0) as f64;
    let telemetry_every = if rig.telemetry_hz > 0.0 && n > 0 {
        1.0 / (rig.telemetry_hz as f64 * n as f64)
    } else {
        f64::INFINITY
    };
    let stream_size = {
        let s = scenario.spec.screen.size;
        let w = opts.stream_width;
        (w, ((w as f32) * s[1] / s[0]).round().max(1.0) as u32)
    };
    let mut clock = ClockOffset::default();
    let mut report = LiveReport::default();
    let mut last_sent: Vec<(WheelCommand, f64)> = vec![(WheelCommand::STOP, f64::NEG_INFINITY); n];
    let mut tick_ms: Vec<f64> = Vec::new();
    // Reused every tick: the behaviours' commands and the commands as sent (after shield and stops).
    let (mut commands, mut sent_now) = (Vec::with_capacity(n), Vec::with_capacity(n));
    let (mut next_telemetry, mut telemetry_robot) = (0.0, 0usize);
    let mut next_frame = 0.0;
    let (mut next_display, mut display_gone) = (0.0, false);
    // Each robot is asked every `n / telemetry_hz` s; five missed answers (at least a second) mean it
    // is gone.
    let answer_timeout = (5.0 * telemetry_every * n as f64).max(1.0);
    let mut answered: Vec<Option<f64>> = vec![None; n];
    let mut silent = vec![false; n];
    let (mut last_tick, mut next, mut last_status) = (start, start, start);
    loop {
        let now = Instant::now();
        let t = now.duration_since(start).as_secs_f64();
        if stop.load(Ordering::Relaxed) || opts.duration.is_some_and(|d| t >= d) {
            break;
        }
        // Poses in.
        if let Some(snapshot) = source.poll() {
            report.pose_blocks += 1;
            beats.tracker();
            let now_epoch = epoch_s();
            let receipt = now_epoch - snapshot.received.elapsed().as_secs_f64();
            clock.observe(snapshot.t, receipt);
            let mut json = Vec::with_capacity(snapshot.poses.len());
            for p in &snapshot.poses {
                let age = clock.age(p.t, now_epoch);
                json.push(serde_json::json!({"id": p.id, "x": p.pose.pos.x, "y": p.pose.pos.y, "heading": p.pose.heading, "age": age, "fresh": p.fresh}));
                let Some(i) = tracker_ids.iter().position(|&id| id as i64 == p.id as i64) else {
                    continue;
                };
                // A lost robot's pose is repeated by the tracker: only a fresh one counts as seen.
                if p.fresh {
                    host.set_pose(i, p.pose, (host.time() as f64 - age) as f32);
                    beats.pose(i);
                }
            }
            record(
                log,
                Topic::Poses,
                serde_json::Value::Array(json).to_string().as_bytes(),
            );
        }
        if matches!(
            source.state(),
            ConnectionState::Disconnected { .. }
                | ConnectionState::Finished
                | ConnectionState::Failed(_)
        ) || source
            .take_events()
            .contains(&crate::swarmcon::TrackerEvent::Closed)
        {
            beats.tracker_closed();
        }
        // Telemetry in.
        let telemetry = link
            .lock()
            .map(|mut l| l.take_telemetry())
            .unwrap_or_default();
        for tm in &telemetry {
            report.telemetry_received += 1;
            record(log, Topic::Telemetry, &tm.to_frame());
            if let Some(i) = radio.iter().position(|&r| r == tm.id) {
                answered[i] = Some(t);
                silent[i] = false;
                let bumpers =
                    std::array::from_fn(|k| bumper_reading(tm.tcrt_on[k], tm.tcrt_off[k]));
                host.set_readings(i, colour_to_sim(tm.colour), bumpers);
            }
        }
        // A robot that has answered before and not for `answer_timeout`: its radio is gone, so it can
        // no longer be stopped from here (its firmware's timeout must); said once, in the log and the
        // report, and its readings are no longer trusted.
        for i in 0..n {
            if let Some(at) = answered[i]
                && !silent[i]
                && t - at > answer_timeout
            {
                silent[i] = true;
                report.silent_robots.push(radio[i]);
                let event = serde_json::json!({"kind": "robot_silent", "robot": i, "detail": format!("radio {} has not answered for {:.2} s", radio[i], t - at)});
                record(log, Topic::Events, event.to_string().as_bytes());
                log::warn!("robot {i} (radio {}) stopped answering", radio[i]);
            }
        }
        // Fields, injection, sensing, decisions, on the measured time since the last tick.
        let step = if report.ticks == 0 {
            dt
        } else {
            now.duration_since(last_tick).as_secs_f64()
        };
        last_tick = now;
        commands.clear();
        commands.extend_from_slice(host.tick(step as f32));
        beats.policy();
        report.ticks += 1;
        // The screen to the frame stream.
        if let Some(server) = frames.as_mut()
            && stream_size.0 > 0
            && t >= next_frame
            && server.subscribers() > 0
        {
            next_frame = t + if opts.stream_hz > 0.0 {
                1.0 / opts.stream_hz
            } else {
                0.0
            };
            let img = host.render(stream_size.0, stream_size.1);
            server.publish(&img, host.time() as f64);
            let json = serde_json::json!({"tick": report.ticks, "width": img.width(), "height": img.height(), "fnv1a": format!("{:016x}", fnv1a(img.as_raw()))});
            record(log, Topic::Frames, json.to_string().as_bytes());
        }
        if let Some(display) = &opts.display
            && !display_gone
            && t >= next_display
        {
            next_display = t + 1.0 / opts.display_hz.clamp(1.0, 50.0);
            let (s, w) = (
                scenario.spec.screen.size,
                opts.display_width.clamp(16, 7680),
            );
            let img = host.render(w, ((w as f32) * s[1] / s[0]).round().max(1.0) as u32);
            if let Ok(mut d) = display.lock()
                && !d.show(&img)
            {
                display_gone = true;
                log::warn!("the display window was closed; the loop goes on without it");
            }
        }
        // Commands out through the shield; unchanged ones again at the keep-alive rate.
        let mut link_error = None;
        sent_now.clear();
        sent_now.extend_from_slice(&commands);
        if let Ok(mut l) = link.lock() {
            for (i, cmd) in commands.iter().enumerate() {
                let (cmd, intervention) = shield.apply(&host.poses()[i], *cmd);
                report.shield.add(intervention);
                let cmd = if beats.is_stopped(i) || !host.tracked()[i].seen || silent[i] {
                    WheelCommand::STOP
                } else {
                    cmd
                };
                sent_now[i] = cmd;
                let (prev, at) = last_sent[i];
                if cmd != prev || t - at >= keepalive {
                    let packet =
                        drive_packet(radio[i], t_ms(start), cmd, rig.firmware, &opts.legacy);
                    l.send(packet);
                    record(log, Topic::Commands, &packet.to_frame());
                    report.commands_sent += 1;
                    last_sent[i] = (cmd, t);
                }
            }
            if t >= next_telemetry {
                let request = CommandPacket::new(
                    radio[telemetry_robot % n],
                    t_ms(start),
                    HostCommand::RequestTelemetry(1),
                );
                l.send(request);
                record(log, Topic::Commands, &request.to_frame());
                telemetry_robot += 1;
                next_telemetry = t + telemetry_every;
            }
            if let Err(e) = l.pump() {
                link_error = Some(e.to_string());
            }
        }
        if let Some(e) = link_error {
            stopper.stop(&StopReason::LinkError(e));
        }
        if let Some(traj) = trajectory.as_mut() {
            traj.record_rows(&TickRows {
                tick: report.ticks,
                time: host.time(),
                poses: host.poses(),
                tracked: host.tracked(),
                obs: host.observations(),
                commands: &sent_now,
                groups: &groups,
                group_specs: &scenario.spec.robots,
            })?;
        }
        if let Ok(mut l) = log.lock()
            && let Some(r) = l.as_mut()
        {
            let _ = r.flush();
        }
        let work = now.elapsed().as_secs_f64() * 1e3;
        tick_ms.push(work);
        if opts.status && now.duration_since(last_status) >= Duration::from_secs(1) {
            last_status = now;
            let seen = host.tracked().iter().filter(|p| p.seen).count();
            let counters = link.lock().map(|l| l.counters()).unwrap_or_default();
            let age = host
                .tracked()
                .iter()
                .filter(|p| p.seen)
                .map(|p| host.time() - p.stamp)
                .fold(0.0f32, f32::max);
            eprint!(
                "\r{t:7.1} s  {:5.1} Hz  tick {work:5.2} ms  oldest pose {:4.0} ms  seen {seen}/{n}  sent {}  queued {}  overruns {}  shield {}/{}   ",
                report.ticks as f64 / t.max(1e-9),
                age * 1e3,
                counters.scheduler.sent,
                counters.pending,
                report.overruns,
                report.shield.capped,
                report.shield.walled,
            );
        }
        next += period;
        let after = Instant::now();
        if after > next {
            report.overruns += 1;
            // Behind: the next tick starts now rather than catching up a backlog.
            next = after;
        } else {
            std::thread::sleep(next - after);
        }
    }
    if opts.status {
        eprintln!();
    }
    report.seconds = start.elapsed().as_secs_f64();
    tick_ms.sort_by(f64::total_cmp);
    report.worst_tick_ms = tick_ms.last().copied().unwrap_or(0.0);
    let p99 = ((tick_ms.len() as f64 * 0.99) as usize).min(tick_ms.len().saturating_sub(1));
    report.p99_tick_ms = tick_ms.get(p99).copied().unwrap_or(0.0);
    report.stops = stops.lock().map(|s| s.clone()).unwrap_or_default();
    Ok(report)
}
