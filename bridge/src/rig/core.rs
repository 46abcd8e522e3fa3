//! One tick of the live loop as a function of its inputs: the poses and telemetry taken this tick, the
//! tick's time, the watchdog's stops and a policy's commands in; command frames out. No clock, socket
//! or file in here, so a recorded run put through it again gives the same command bytes (a replay),
//! and the Python plants step it with a policy's actions.
use super::host::HostWorld;
use super::onboard_supervisor::OnboardSupervisor;
use super::stopper::{drive_packet, t_ms};
use crate::protocol::colias::{CommandPacket, HostCommand, LegacyDrive, Telemetry, colour_to_sim};
use crate::twin::bumper_reading;
use colcos_sim::behaviour::WheelCommand;
use colcos_sim::error::Result;
use colcos_sim::robot::Pose;
use colcos_sim::scenario::{Firmware, Scenario};
use colcos_sim::shield::{Intervention, Shield, ShieldCounts};

/// One tracked robot as the loop takes it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PoseIn {
    /// Tracker ID.
    pub id: u32,
    pub pose: Pose,
    /// Seconds since the camera captured it.
    pub age: f64,
    /// Detected in the newest camera frame (false: the tracker repeats a lost robot's last pose).
    pub fresh: bool,
}

/// Everything one tick depends on.
#[derive(Clone, Copy, Debug, Default)]
pub struct TickInput<'a> {
    /// Seconds since the loop started.
    pub t: f64,
    /// Seconds the fields advance this tick (the measured time since the last tick).
    pub step: f64,
    /// The newest pose block, if one arrived since the last tick.
    pub poses: &'a [PoseIn],
    pub telemetry: &'a [Telemetry],
    /// Robots the watchdog holds stopped (empty: none).
    pub stopped: &'a [bool],
    /// Commands that replace the behaviours' for some robots (a policy's agents); empty: none.
    pub overrides: &'a [Option<WheelCommand>],
}

/// Running totals of the loop.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CoreCounters {
    pub ticks: u64,
    pub commands_sent: u64,
    pub telemetry_received: u64,
    pub shield: ShieldCounts,
    /// Radio addresses of robots that stopped answering, in the order they fell silent.
    pub silent_robots: Vec<u8>,
}

pub struct LoopCore {
    host: HostWorld,
    shield: Shield,
    radio: Vec<u8>,
    tracker_ids: Vec<i32>,
    firmware: Firmware,
    legacy: LegacyDrive,
    keepalive: f64,
    last_sent: Vec<(WheelCommand, f64)>,
    poll: TelemetryPoll,
    counters: CoreCounters,
    // The last tick's outputs, reused.
    fresh: Vec<usize>,
    packets: Vec<CommandPacket>,
    sent: Vec<WheelCommand>,
    interventions: Vec<Intervention>,
    events: Vec<String>,
    /// The rig's calibrations (`[rig] colour_calibration`: robots' counts through their calibrated
    /// inverse onto the scenario's sensor model; `[rig] compensate`: commands and counts through
    /// each robot's identified wheel scales and sensor gain).
    calibration: crate::calibrate::RigCalibration,
    nominal: colcos_sim::sensors::ColourSensor,
    /// The robots run a policy of their own (`[rig] onboard`): the host sends only its parameters,
    /// starts and stops.
    onboard: Option<OnboardSupervisor>,
}

/// The data requests, one robot at a time in turn, and who answers them.
struct TelemetryPoll {
    every: f64,
    next: f64,
    robot: usize,
    /// A robot that has not answered for this long (since its last answer, or since it was first
    /// asked), s, is silent.
    answer_timeout: f64,
    answered: Vec<Option<f64>>,
    /// When each robot was first asked for data: one that never answers is silent too.
    first_asked: Vec<Option<f64>>,
    silent: Vec<bool>,
}

impl TelemetryPoll {
    /// Requests to `n` robots, `hz` a second to each (0: none).
    fn new(hz: f32, n: usize) -> TelemetryPoll {
        let every = if hz > 0.0 && n > 0 {
            1.0 / (hz as f64 * n as f64)
        } else {
            f64::INFINITY
        };
        TelemetryPoll {
            every,
            next: 0.0,
            robot: 0,
            // Each robot is asked every `n / hz` s; five missed answers (at least a second) mean it
            // is gone.
            answer_timeout: (5.0 * every * n as f64).max(1.0),
            answered: vec![None; n],
            first_asked: vec![None; n],
            silent: vec![false; n],
        }
    }

    /// Robot `i` answered at `t`.
    fn answer(&mut self, i: usize, t: f64) {
        self.answered[i] = Some(t);
        self.silent[i] = false;
    }

    /// Whether robot `i` falls silent at `t` (once, until it answers again): the seconds since its
    /// last answer or first request, and whether it ever answered.
    fn falls_silent(&mut self, i: usize, t: f64) -> Option<(f64, bool)> {
        let since = self.answered[i].or(self.first_asked[i]);
        if let Some(at) = since
            && !self.silent[i]
            && t - at > self.answer_timeout
        {
            self.silent[i] = true;
            return Some((t - at, self.answered[i].is_some()));
        }
        None
    }

    /// The robot of `n` to ask for data at `t`, if a request is due.
    fn due(&mut self, t: f64, n: usize) -> Option<usize> {
        if t < self.next || n == 0 {
            return None;
        }
        let k = self.robot % n;
        self.first_asked[k].get_or_insert(t);
        self.robot += 1;
        self.next = t + self.every;
        Some(k)
    }
}

impl LoopCore {
    /// The loop for `scenario`'s robots and `[rig]` section; `legacy` maps wheel speeds onto old
    /// firmware's motion commands.
    pub fn new(scenario: &Scenario, legacy: LegacyDrive) -> Result<LoopCore> {
        Self::with_index(scenario, legacy, 0)
    }

    /// [`LoopCore::new`] with the behaviours' random streams of world index `index` (an episode).
    pub fn with_index(scenario: &Scenario, legacy: LegacyDrive, index: u64) -> Result<LoopCore> {
        let rig = scenario.spec.rig.clone();
        let calibration = crate::calibrate::RigCalibration::load(scenario).map_err(|e| {
            colcos_sim::error::SimError::invalid("rig", "(calibration)", e.to_string())
        })?;
        let mut host = HostWorld::with_index(scenario, rig.sensors, index)?;
        host.set_latency(rig.latency);
        let n = host.robot_count();
        let radio = rig.radio_addresses(n)?;
        let onboard = crate::onboard::OnboardManifest::of_scenario(scenario)?
            .map(|m| OnboardSupervisor::new(&m, scenario, calibration.colour.as_ref(), &radio));
        Ok(LoopCore {
            shield: Shield::new(
                rig.shield,
                scenario.arena_size(),
                scenario.spec.robot.max_wheel_speed,
            ),
            radio,
            tracker_ids: (0..n).map(|i| rig.tracker_id(i)).collect(),
            firmware: rig.firmware,
            legacy,
            keepalive: 1.0 / rig.keepalive_hz.max(1.0) as f64,
            last_sent: vec![(WheelCommand::STOP, f64::NEG_INFINITY); n],
            poll: TelemetryPoll::new(rig.telemetry_hz, n),
            counters: CoreCounters::default(),
            fresh: Vec::with_capacity(n),
            packets: Vec::with_capacity(n + 1),
            sent: vec![WheelCommand::STOP; n],
            interventions: vec![Intervention::default(); n],
            events: Vec::new(),
            calibration,
            nominal: colcos_sim::sensors::ColourSensor::new(scenario.spec.sensor),
            onboard,
            host,
        })
    }

    pub fn host(&self) -> &HostWorld {
        &self.host
    }
    pub fn host_mut(&mut self) -> &mut HostWorld {
        &mut self.host
    }
    pub fn robot_count(&self) -> usize {
        self.radio.len()
    }
    /// Each robot's radio address.
    pub fn radio(&self) -> &[u8] {
        &self.radio
    }
    pub fn firmware(&self) -> Firmware {
        self.firmware
    }
    pub fn counters(&self) -> &CoreCounters {
        &self.counters
    }
    /// The robot a tracker ID belongs to.
    pub fn robot_of(&self, tracker_id: u32) -> Option<usize> {
        self.tracker_ids
            .iter()
            .position(|&id| id as i64 == tracker_id as i64)
    }
    /// Robots with a fresh pose in the last tick.
    pub fn fresh(&self) -> &[usize] {
        &self.fresh
    }
    /// Robots that have stopped answering data requests.
    pub fn silent(&self) -> &[bool] {
        &self.poll.silent
    }
    /// The frames the last tick sent, in order.
    pub fn packets(&self) -> &[CommandPacket] {
        &self.packets
    }
    /// The command each robot was last given (after the shield and the stops).
    pub fn sent(&self) -> &[WheelCommand] {
        &self.sent
    }
    /// What the shield did to each robot's command in the last tick.
    pub fn interventions(&self) -> &[Intervention] {
        &self.interventions
    }
    /// JSON events of the last tick (a robot fell silent), for the log.
    pub fn take_events(&mut self) -> Vec<String> {
        std::mem::take(&mut self.events)
    }

    /// One tick: takes the poses and telemetry, steps the host, decides, shields and stops the
    /// commands, and lists the frames to send in [`LoopCore::packets`].
    pub fn tick(&mut self, input: &TickInput) {
        let t = input.t;
        self.fresh.clear();
        for p in input.poses {
            // A lost robot's pose is repeated by the tracker: only a fresh one counts as seen.
            if let Some(i) = self.robot_of(p.id)
                && p.fresh
            {
                // Captured `age` s before this tick, whose host time is `time + step`.
                let stamp = (self.host.time() as f64 + input.step - p.age) as f32;
                self.host.set_pose(i, p.pose, stamp);
                self.fresh.push(i);
            }
        }
        for tm in input.telemetry {
            self.counters.telemetry_received += 1;
            if let Some(i) = self.radio.iter().position(|&r| r == tm.id) {
                self.poll.answer(i, t);
                let bumpers =
                    std::array::from_fn(|k| bumper_reading(tm.tcrt_on[k], tm.tcrt_off[k]));
                let counts = self.calibration.robot_counts(
                    i,
                    tm.id,
                    colour_to_sim(tm.colour),
                    &self.nominal,
                );
                self.host.set_readings(i, counts, bumpers);
                if let Some(event) = self.onboard.as_mut().and_then(|o| o.take_telemetry(i, tm)) {
                    self.events.push(event);
                }
            }
        }
        // A silent robot: its radio is gone, so it can no longer be stopped from here (its
        // firmware's timeout must); said once, and its readings are no longer trusted.
        for i in 0..self.radio.len() {
            if let Some((quiet, ever_answered)) = self.poll.falls_silent(i, t) {
                self.counters.silent_robots.push(self.radio[i]);
                let detail = if ever_answered {
                    format!("radio {} has not answered for {quiet:.2} s", self.radio[i])
                } else {
                    format!(
                        "radio {} has never answered ({quiet:.2} s since asked)",
                        self.radio[i]
                    )
                };
                self.events.push(
                    serde_json::json!({"kind": "robot_silent", "robot": i, "detail": detail})
                        .to_string(),
                );
                log::warn!("robot {i} (radio {}) stopped answering", self.radio[i]);
            }
        }
        let step = input.step;
        self.host.tick(step as f32);
        self.counters.ticks += 1;
        self.packets.clear();
        let stamp = t_ms(t);
        for i in 0..self.radio.len() {
            let stopped = input.stopped.get(i).copied().unwrap_or(false);
            if let Some(onboard) = &mut self.onboard {
                // The robot drives itself; the shield can only look ahead and stop it.
                let cmd = onboard.intent(i);
                let (_, intervention) = self.shield.apply(&self.host.poses()[i], cmd);
                self.interventions[i] = intervention;
                self.counters.shield.add(intervention);
                let hold = stopped
                    || !self.host.tracked()[i].seen
                    || self.poll.silent[i]
                    || intervention.walled;
                let drives = onboard.frames(
                    i,
                    t,
                    stamp,
                    hold,
                    self.keepalive,
                    self.firmware,
                    &mut self.packets,
                );
                self.sent[i] = if drives { cmd } else { WheelCommand::STOP };
                continue;
            }
            let mut cmd = self.host.commands()[i];
            if let Some(Some(o)) = input.overrides.get(i) {
                cmd = *o;
            }
            // A held robot is sent a stop, which the shield has nothing to change: counting its
            // turned command would charge the behaviour for a robot that did not drive.
            let held = stopped || !self.host.tracked()[i].seen || self.poll.silent[i];
            let (cmd, intervention) = if held {
                (WheelCommand::STOP, Intervention::default())
            } else {
                self.shield.apply(&self.host.poses()[i], cmd)
            };
            self.interventions[i] = intervention;
            self.counters.shield.add(intervention);
            self.sent[i] = cmd;
            let (prev, at) = self.last_sent[i];
            if cmd != prev || t - at >= self.keepalive {
                // The host models the nominal robot; the radio carries what makes this one drive so.
                self.packets.push(drive_packet(
                    self.radio[i],
                    stamp,
                    self.calibration.robot_command(i, cmd),
                    self.firmware,
                    &self.legacy,
                ));
                self.last_sent[i] = (cmd, t);
            }
        }
        self.host.drive(&self.sent, step as f32);
        if let Some(k) = self.poll.due(t, self.radio.len()) {
            self.packets.push(CommandPacket::new(
                self.radio[k],
                stamp,
                HostCommand::RequestTelemetry(1),
            ));
        }
        self.counters.commands_sent += self.packets.len() as u64;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A robot driving at a wall is shielded while it drives, and not while it is held stopped (the
    /// stop goes out unchanged and counts as no intervention).
    #[test]
    fn a_held_robot_at_a_wall_is_sent_a_stop_and_not_counted_as_shielded() {
        let text = "duration = 5.0\n[screen]\nresolution = [640, 640]\nsize = [0.5, 0.5]\n\
                    [[robots]]\ncount = 1\nbehaviour = \"wander\"\n";
        let sc = Scenario::from_toml_str(text, ".").unwrap();
        let mut core = LoopCore::new(&sc, LegacyDrive::default()).unwrap();
        let pose = PoseIn {
            id: sc.spec.rig.tracker_id(0) as u32,
            pose: Pose::new(0.04, 0.25, std::f32::consts::PI),
            age: 0.0,
            fresh: true,
        };
        let forward = [Some(WheelCommand::new(0.2, 0.2))];
        let mut tick = |t: f64, held: bool| {
            core.tick(&TickInput {
                t,
                step: 0.02,
                poses: std::slice::from_ref(&pose),
                telemetry: &[],
                stopped: &[held],
                overrides: &forward,
            });
            (core.sent()[0], core.interventions()[0])
        };
        let (sent, shield) = tick(0.02, true);
        assert_eq!(
            (sent, shield),
            (WheelCommand::STOP, Intervention::default())
        );
        let (sent, shield) = tick(0.04, false);
        assert!(shield.walled && sent.left == -sent.right, "{sent:?}");
        assert_eq!(core.counters().shield.walled, 1);
    }
}
