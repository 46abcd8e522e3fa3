//! [`LiveEnv`]: one arena of a plant as an RL environment, with the buffers of one world of `VecEnv`.
use crate::calibration_gate;
use crate::driver::{self, Driver, TwinThread};
use crate::{GoTo, PlantError, PlantKind, PlantOptions};
use colcos_bridge::calibrate::RigCalibration;
use colcos_bridge::protocol::colias::LegacyDrive;
use colcos_bridge::rig::HostWorld;
use colcos_bridge::rig::{FrameRate, LiveOptions, LiveSession, LoopCore, RigEnds, replay};
use colcos_bridge::transport::FrameServer;
use colcos_bridge::{SourceOptions, open_pose_source, open_robot_link};
use colcos_env::task::registry;
use colcos_env::world_output::render_world;
use colcos_env::{
    ActionDecoder, Actions, EnvConfig, EnvSpec, Episode, Outputs, StepEnd, Task, VecEnv, Writer,
    shield_bits,
};
use colcos_sim::behaviour::WheelCommand;
use colcos_sim::robot::Pose;
use colcos_sim::scenario::{Scenario, SensorSource};
use colcos_sim::world::WorldParts;
use std::time::Instant;

/// The frames the host streams to a twin started here whose robots read their own sensors: wide
/// enough for a sensor's footprint to cover a few pixels, at twice the default telemetry rate.
const TWIN_FRAMES: FrameRate = FrameRate::new(480, 10.0);

/// What the last reset's go-to did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct GoToReport {
    pub seconds: f64,
    /// Robots at their start pose when it ended.
    pub arrived: usize,
    pub robots: usize,
}

/// One arena of a plant as an RL environment: the buffers of one world of `VecEnv` (`[1, N, ...]`),
/// allocated once and overwritten by every `reset` and `step`.
pub struct LiveEnv {
    pub(crate) spec: EnvSpec,
    task: Box<dyn Task>,
    scenario: Scenario,
    kind: PlantKind,
    driver: Driver,
    goto: Option<(GoTo, f64)>,
    goto_report: GoToReport,
    writer: Writer,
    overrides: Vec<Option<WheelCommand>>,
    pub(crate) decoder: ActionDecoder,
    /// Scratch: the agents' decoded commands and deposit rates.
    commands: Vec<WheelCommand>,
    deposit_rates: Vec<f32>,
    episode: Episode,
    needs_reset: bool,
    /// A deferred step (a task written in Python) waits for `conclude` with how it ended.
    pub(crate) awaiting: Option<StepEnd>,
    /// The outputs of one world (`[1, N, ...]`), as the batch's.
    out: Outputs,
    /// The live loop's report as it was when the plant was closed.
    closed: Option<Option<colcos_bridge::rig::LiveReport>>,
}

impl LiveEnv {
    /// The environment `cfg` describes (one world) on the plant `plant` names.
    pub fn new(cfg: &EnvConfig, plant: &PlantOptions) -> Result<LiveEnv, PlantError> {
        // The simulated environment of the same configuration gives the spec, so every plant has
        // the same spaces, names and sizes.
        let one = EnvConfig {
            num_envs: 1,
            num_threads: Some(1),
            ..cfg.clone()
        };
        let sim = VecEnv::new(&one)?;
        let (spec, decoder) = (sim.spec().clone(), sim.action_decoder().clone());
        let (task, mut scenario) = registry::build(&cfg.task, &cfg.scenario, &cfg.params)?;
        scenario.spec.seed = cfg.seed;
        if let Some(p) = cfg.physics {
            scenario.spec.physics = p;
        }
        driver::refuse_onboard(&scenario)?;
        let driver = Self::open(&scenario, plant)?;
        let p = &scenario.spec.robot;
        let goto = (plant.goto && plant.kind != PlantKind::Replay).then(|| {
            let speed = p
                .max_wheel_speed
                .min(scenario.spec.rig.shield.max_wheel_speed)
                * 0.5;
            (
                GoTo::new(speed, p.wheel_base, p.radius),
                plant.goto_timeout.clamp(0.0, 600.0),
            )
        });
        let (n, robots) = (spec.num_agents, spec.num_robots);
        let writer = Writer {
            max_speed: p.max_wheel_speed,
            max_cycles: spec.max_cycles,
            state: spec.state.is_some(),
            patch: cfg.patch,
        };
        Ok(LiveEnv {
            writer,
            task,
            kind: plant.kind,
            driver,
            goto,
            goto_report: GoToReport::default(),
            overrides: vec![None; robots],
            commands: vec![WheelCommand::STOP; n],
            deposit_rates: vec![0.0; n * decoder.deposits()],
            decoder,
            episode: Episode::new(0, n),
            needs_reset: true,
            awaiting: None,
            // The task's extra entries (a carrying flag) included, as the spec says.
            out: Outputs::new(&spec),
            closed: None,
            spec,
            scenario,
        })
    }

    fn open(scenario: &Scenario, plant: &PlantOptions) -> Result<Driver, PlantError> {
        if plant.kind == PlantKind::Replay {
            let path = plant.log.as_ref().ok_or_else(|| {
                PlantError::option("replay", "a replay plant needs a rig log (rig.mcap)")
            })?;
            let bytes = std::fs::read(path)
                .map_err(|e| PlantError::option("replay", format!("{}: {e}", path.display())))?;
            refuse_another_scenario(&bytes, path, scenario)?;
            let log = colcos_bridge::rig::recorder::read_log(&bytes);
            let ticks = replay::ticks_of(&log, scenario.robot_count())?;
            let episodes = driver::episode_ranges(&log, &ticks);
            return Ok(Driver::Replay {
                core: Box::new(LoopCore::new(scenario, LegacyDrive::default())?),
                ticks,
                episodes,
                next: 0,
                end: 0,
            });
        }
        let local =
            plant.kind == PlantKind::Twin && plant.tracker.is_none() && plant.robots.is_none();
        if (plant.twin_scenario.is_some() || plant.twin_truth.is_some()) && !local {
            let key = if plant.twin_scenario.is_some() {
                "twin_scenario"
            } else {
                "truth"
            };
            return Err(PlantError::option(
                key,
                "only a twin started here (plant twin, no `tracker`/`robots` URLs) plays its own \
                 scenario; a twin elsewhere takes its scenario where it is started (`colcos twin`)",
            ));
        }
        // Robots reading their own sensors: the twin's readings come from the frames the host
        // shows, as on the rig's LCD, so the host streams them to it.
        let frames = (local && scenario.spec.rig.sensors == SensorSource::Robot)
            .then(|| FrameServer::bind("127.0.0.1:0"))
            .transpose()
            .map_err(|e| PlantError::Io(format!("starting the frame stream for the twin: {e}")))?;
        let twin = match (plant.kind, &plant.tracker, &plant.robots) {
            (PlantKind::Twin, None, None) => {
                let mut own = match &plant.twin_scenario {
                    Some(t) => t.resolve(scenario)?,
                    None => scenario.clone(),
                };
                if let Some(truth) = &plant.twin_truth {
                    own = own.with_truth(truth)?;
                }
                Some(TwinThread::start_seeing(
                    &own,
                    frames.as_ref().map(|f| f.local_addr()),
                )?)
            }
            (_, Some(_), Some(_)) => None,
            (kind, _, _) => {
                let which = if kind == PlantKind::Rig {
                    "rig"
                } else {
                    "twin"
                };
                return Err(PlantError::option(
                    "tracker",
                    format!(
                        "a {which} plant needs both `tracker` and `robots` URLs{}",
                        if kind == PlantKind::Twin {
                            " (or neither, to start a twin here)"
                        } else {
                            ""
                        }
                    ),
                ));
            }
        };
        let (tracker, robots) = match &twin {
            Some(t) => (t.tracker_url.clone(), t.robots_url.clone()),
            None => (
                plant.tracker.clone().unwrap_or_default(),
                plant.robots.clone().unwrap_or_default(),
            ),
        };
        let calibration = RigCalibration::load(scenario)
            .map_err(|e| PlantError::option("rig.screen_calibration", e.to_string()))?;
        if plant.kind == PlantKind::Rig {
            calibration_gate::check(&calibration, &plant.calibration)?;
        }
        let opts = SourceOptions::new(calibration.frame_transform(scenario));
        let source = open_pose_source(&tracker, &opts)?;
        let link = open_robot_link(&robots)?;
        let live = LiveOptions {
            log: plant.log.clone(),
            stream: TWIN_FRAMES,
            ..LiveOptions::default()
        };
        let ends = RigEnds {
            source,
            link,
            frames,
        };
        let session = LiveSession::new(scenario, ends, live)?;
        Ok(Driver::Live {
            session: Box::new(session),
            tracker,
            robots,
            _twin: twin,
        })
    }

    pub fn spec(&self) -> &EnvSpec {
        &self.spec
    }
    pub fn kind(&self) -> PlantKind {
        self.kind
    }
    pub fn scenario(&self) -> &Scenario {
        &self.scenario
    }
    /// The host: the tracked poses as used, the fields, the robots' observations.
    pub fn host(&self) -> &HostWorld {
        self.driver.host()
    }
    pub fn episode(&self) -> u64 {
        self.episode.index
    }
    pub fn episode_steps(&self) -> u64 {
        self.episode.steps
    }
    pub fn goto_report(&self) -> GoToReport {
        self.goto_report
    }
    /// The output buffers (`[1, N, ...]`), overwritten by every reset and step.
    pub fn outputs(&self) -> &Outputs {
        &self.out
    }
    /// Raw pointers to the output buffers, for bindings that hand out views (see [`Outputs::ptrs`]).
    pub fn buffer_ptrs(&mut self) -> colcos_env::BufferPtrs {
        self.out.ptrs()
    }

    /// The screen with the robots on it (agents white), `width` px wide.
    pub fn render(&self, width: u32) -> image::RgbImage {
        render_world(self.driver.host(), self.task.agents(), width)
    }

    /// A new episode: a `seed` becomes the scenario's seed and restarts the episode count. On the
    /// twin and the rig the robots are first driven to the episode's start poses (if asked to).
    pub fn reset(&mut self, seed: Option<u64>) -> Result<(), PlantError> {
        self.refuse_closed()?;
        // A deferred step not concluded is dropped with its episode.
        self.awaiting = None;
        // Nothing is driven, and no observation is made, before every robot has been tracked.
        self.driver.await_poses()?;
        if let Some(s) = seed {
            self.scenario.spec.seed = s;
        }
        let episode = if seed.is_some() || self.needs_reset {
            0
        } else {
            self.episode.index + 1
        };
        let index = colcos_env::world_index(0, episode);
        if !self.needs_reset {
            self.driver.mark_end();
        }
        if let Some((goto, timeout)) = self.goto {
            let targets = WorldParts::build(&self.scenario, index)?.poses;
            self.goto_report = self.drive_to(&goto, &targets, timeout)?;
        }
        self.driver.restart(&self.scenario, index, episode)?;
        self.task.on_reset(self.driver.host_mut().pheromones_mut());
        // One tick with the agents still, so that their observations are of this episode.
        self.overrides.fill(None);
        for &i in self.task.agents() {
            self.overrides[i] = Some(WheelCommand::STOP);
        }
        self.driver.tick(&self.overrides)?;
        self.episode.restart(episode);
        self.needs_reset = false;
        self.out.clear();
        self.write_outputs();
        Ok(())
    }

    /// Drives every robot toward `targets` until all are there or `timeout` s have passed.
    fn drive_to(
        &mut self,
        goto: &GoTo,
        targets: &[Pose],
        timeout: f64,
    ) -> Result<GoToReport, PlantError> {
        let start = Instant::now();
        let n = targets.len();
        let mut arrived = 0;
        while start.elapsed().as_secs_f64() < timeout {
            let host = self.driver.host();
            let poses = host.poses();
            arrived = 0;
            for i in 0..n {
                let (cmd, there) = if host.tracked()[i].seen {
                    goto.command(i, poses, targets)
                } else {
                    (WheelCommand::STOP, false)
                };
                arrived += there as usize;
                self.overrides[i] = Some(cmd);
            }
            if arrived == n {
                break;
            }
            self.driver.tick(&self.overrides)?;
        }
        Ok(GoToReport {
            seconds: start.elapsed().as_secs_f64(),
            arrived,
            robots: n,
        })
    }

    /// One step: continuous actions `[N, 2 + D]` (wheels as fractions of the largest wheel speed,
    /// then deposit rates) or discrete ones `[N]`, decoded as the simulated batch decodes them.
    /// Terminated agents are stopped and their actions ignored.
    pub fn step(&mut self, actions: Actions) -> Result<(), PlantError> {
        let end = self.advance(actions)?;
        self.finish(end, None);
        Ok(())
    }

    /// The arena's part of a step: the actions decoded and sent, one tick.
    pub(crate) fn advance(&mut self, actions: Actions) -> Result<StepEnd, PlantError> {
        self.refuse_closed()?;
        if self.awaiting.is_some() {
            return Err(PlantError::State(
                "the last step awaits its rewards: call conclude() first".into(),
            ));
        }
        if self.needs_reset {
            return Err(PlantError::State("call reset() before step()".into()));
        }
        if self.episode.done {
            return Err(PlantError::State(
                "the episode has ended: call reset() before stepping again".into(),
            ));
        }
        self.decoder
            .decode(actions, 1, &mut self.commands, &mut self.deposit_rates)?;
        self.overrides.fill(None);
        let d = self.decoder.deposits();
        let host = self.driver.host_mut();
        for (k, (&i, &term)) in (self.task.agents().iter())
            .zip(&self.episode.terminated)
            .enumerate()
        {
            // A terminated agent is stopped and lays nothing.
            self.overrides[i] = Some(if term {
                WheelCommand::STOP
            } else {
                self.commands[k]
            });
            let lay = self.deposit_rates[k * d..(k + 1) * d].iter();
            host.set_deposit_actions(i, lay.map(|&f| if term { 0.0 } else { f }));
        }
        Ok(match self.driver.tick(&self.overrides)? {
            false => StepEnd::Nothing,
            true if self.driver.remaining() == Some(0) => StepEnd::LastStep,
            true => StepEnd::Stepped,
        })
    }

    /// The end of a step: the task's (or the `given`) rewards and terminations, the shield's
    /// flags, the outputs.
    pub(crate) fn finish(&mut self, end: StepEnd, given: Option<(&[f32], &[bool])>) {
        let mut world = self.out.world(0);
        let out = world.agent_out();
        let max = self.spec.max_cycles;
        let done = match given {
            Some((r, t)) => self.episode.finish_given(r, t, max, end, out),
            None => {
                (self.episode).finish_step(self.task.as_ref(), self.driver.host(), max, end, out)
            }
        };
        let interventions = self.driver.interventions();
        for ((&i, &was), flags) in (self.task.agents().iter())
            .zip(&self.episode.was_terminated)
            .zip(world.shield.iter_mut())
        {
            *flags = if was {
                0
            } else {
                shield_bits(interventions[i])
            };
        }
        debug_assert_eq!(done, self.episode.done);
        self.write_outputs();
    }

    fn write_outputs(&mut self) {
        let out = &mut self.out.world(0);
        (self.writer).write(self.task.as_ref(), self.driver.host(), &self.episode, out);
    }

    /// Stops every robot now (twin, rig).
    pub fn stop_all(&self, why: &str) {
        if let Driver::Live { session, .. } = &self.driver {
            session.stop_all(why);
        }
    }

    fn refuse_closed(&self) -> Result<(), PlantError> {
        match self.closed {
            Some(_) => Err(driver::closed_error()),
            None => Ok(()),
        }
    }

    /// Stops every robot for `why` and lets go of the tracker, the link and a twin started here:
    /// `reset` and `step` fail from now on, so a closed plant never drives again. Idempotent.
    pub fn close(&mut self, why: &str) {
        if self.closed.is_some() {
            return;
        }
        if let Driver::Live { session, .. } = &self.driver {
            session.stop_all(why);
        }
        let report = self.live_report();
        if let Err(e) = self.driver.close(&self.scenario) {
            log::warn!("closing the plant: {e}");
        }
        self.closed = Some(report);
    }

    pub fn is_closed(&self) -> bool {
        self.closed.is_some()
    }

    /// The live loop's measurements so far (ticks, overruns, shield, stops, `shutdown` for each
    /// stop on closing or asked for); None for a replay.
    pub fn live_report(&self) -> Option<colcos_bridge::rig::LiveReport> {
        if let Some(r) = &self.closed {
            return r.clone();
        }
        match &self.driver {
            Driver::Live { session, .. } => Some(session.report()),
            Driver::Replay { .. } | Driver::Closed { .. } => None,
        }
    }
    /// Seconds since the plant started (live) or the replay's recorded time.
    pub fn time(&self) -> f64 {
        self.driver.time()
    }
}

/// A plant's arena as the one arena a policy reads (a hand-written baseline on the twin or the rig).
impl colcos_env::baseline::Arenas for LiveEnv {
    fn made(&self) -> colcos_env::baseline::Made<'_> {
        (&self.spec, &self.scenario, &self.out, &self.decoder)
    }
    fn arena(&self, _w: usize) -> &dyn colcos_sim::world::ArenaView {
        self.driver.host()
    }
    fn episode(&self, _w: usize) -> &Episode {
        &self.episode
    }
}

/// A rig log recorded with another scenario (its `rig` metadata names it and its robot count) is
/// refused: its poses would be fed to the wrong robots. Logs without that metadata are taken.
fn refuse_another_scenario(
    bytes: &[u8],
    path: &std::path::Path,
    scenario: &Scenario,
) -> Result<(), PlantError> {
    let rig = colcos_bridge::rig::recorder::read_metadata(bytes)
        .into_iter()
        .find(|(name, _)| name == "rig");
    let Some((_, meta)) = rig else {
        return Ok(());
    };
    let (ours, n) = (&scenario.spec.name, scenario.robot_count());
    let robots = meta.get("robots").and_then(|r| r.parse::<usize>().ok());
    let name = meta.get("scenario");
    if robots.is_some_and(|r| r != n) || name.is_some_and(|s| s != ours) {
        return Err(PlantError::option(
            "replay",
            format!(
                "{} was recorded with scenario {:?} ({} robots); this environment's scenario is \
                 {ours:?} ({n} robots)",
                path.display(),
                name.map_or("?", String::as_str),
                robots.map_or("?".to_string(), |r| r.to_string()),
            ),
        ));
    }
    Ok(())
}
