//! The twin's arena: the simulator with its robots obeying the wheel commands that arrive over the
//! link instead of their behaviours, and stopping by themselves when they hear nothing for a while,
//! as the firmware must. Poses go out through the tracker model; colour readings come from the frames
//! the bridge displays.
use colcos_sim::behaviour::WheelCommand;
use colcos_sim::error::Result;
use colcos_sim::rng::{self, SimRng, Stream};
use colcos_sim::robot::Pose;
use colcos_sim::scenario::Scenario;
use colcos_sim::sensors::{SENSOR_RADIUS, sensor_positions};
use colcos_sim::tracker::TrackedPose;
use colcos_sim::world::World;
use glam::Vec2;
use image::RgbImage;

/// How long a robot keeps its last command without hearing another, s (the firmware's timeout).
pub const FIRMWARE_TIMEOUT: f64 = 0.5;

pub struct TwinArena {
    world: World,
    commands: Vec<WheelCommand>,
    /// Twin time each robot last heard a command for it, s.
    heard: Vec<f64>,
    /// Per robot: a stream for the noise of its telemetry readings.
    telemetry_rng: Vec<SimRng>,
}

impl TwinArena {
    pub fn new(scenario: &Scenario) -> Result<TwinArena> {
        let world = World::new(scenario)?;
        let n = world.robot_count();
        let seed = scenario.spec.seed;
        Ok(TwinArena {
            world,
            commands: vec![WheelCommand::STOP; n],
            heard: vec![f64::NEG_INFINITY; n],
            telemetry_rng: (0..n)
                .map(|i| rng::stream_of(seed, 0, Stream::Telemetry(i)))
                .collect(),
        })
    }

    pub fn world(&self) -> &World {
        &self.world
    }
    pub fn robot_count(&self) -> usize {
        self.commands.len()
    }
    /// Twin time, s.
    pub fn time(&self) -> f64 {
        self.world.time() as f64
    }
    /// The command robot `i` drives with now.
    pub fn command(&self, i: usize) -> WheelCommand {
        self.commands.get(i).copied().unwrap_or(WheelCommand::STOP)
    }

    /// Robot `i` (or every robot, `None`) heard `cmd`.
    pub fn hear(&mut self, robot: Option<usize>, cmd: WheelCommand) {
        let now = self.time();
        let cmd = if cmd.left.is_finite() && cmd.right.is_finite() {
            cmd
        } else {
            WheelCommand::STOP
        };
        match robot {
            Some(i) if i < self.commands.len() => {
                self.commands[i] = cmd;
                self.heard[i] = now;
            }
            Some(_) => {}
            None => {
                self.commands.fill(cmd);
                self.heard.fill(now);
            }
        }
    }

    /// Robot `i` heard a frame for it that is not a drive command (its on-board policy's link
    /// activity): its timeout starts again, its command stays.
    pub fn keep_alive(&mut self, i: usize) {
        let now = self.time();
        if let Some(h) = self.heard.get_mut(i) {
            *h = now;
        }
    }
    /// Robot `i` drives with `cmd` of its own choosing (its on-board policy); the link timeout runs on.
    pub fn drive(&mut self, i: usize, cmd: WheelCommand) {
        if let Some(c) = self.commands.get_mut(i)
            && cmd.left.is_finite()
            && cmd.right.is_finite()
        {
            *c = cmd;
        }
    }
    /// Seconds since robot `i` last heard a frame for it.
    pub fn heard_age(&self, i: usize) -> f64 {
        self.time() - self.heard.get(i).copied().unwrap_or(f64::NEG_INFINITY)
    }

    /// One step of the scenario's `dt`; robots that have heard nothing for [`FIRMWARE_TIMEOUT`] stop.
    pub fn step(&mut self) {
        let now = self.time();
        for (c, h) in self.commands.iter_mut().zip(&self.heard) {
            if now - h > FIRMWARE_TIMEOUT {
                *c = WheelCommand::STOP;
            }
        }
        self.world.step_with_commands(&self.commands);
    }

    /// True poses.
    pub fn poses(&self) -> &[Pose] {
        self.world.poses()
    }
    /// Poses as the tracker model delivers them (noise, latency, dropouts).
    pub fn tracked(&self) -> &[TrackedPose] {
        self.world.tracked()
    }

    /// Robot `i`'s colour counts in the simulator's sensor order (n = 0..3), read from `frame` (the
    /// panel as the bridge displays it) at the robot's true pose; without a frame, the simulated
    /// screen's.
    pub fn colour_counts(&mut self, i: usize, frame: Option<&RgbImage>) -> [[u16; 3]; 4] {
        let Some(pose) = self.world.poses().get(i).copied() else {
            return [[0; 3]; 4];
        };
        match frame {
            Some(frame) => {
                let size = Vec2::from(self.world.screen().size);
                let points = sensor_positions(&pose, SENSOR_RADIUS);
                let rng = &mut self.telemetry_rng[i];
                let mut counts = match self.world.robot_sensors(i) {
                    // The scenario's per-robot sensors (`[sensor] per_robot`): each of the four
                    // its own model, read in order.
                    Some(own) => std::array::from_fn(|k| {
                        own.truth[k].read_frame(frame, size, &[points[k]], rng)[0]
                    }),
                    None => self.world.sensor().read_frame(frame, size, &points, rng),
                };
                // The robot's own gain and offset (`[individual]`, a twin's `--truth`), as the
                // simulator applies them to what its sensors deliver.
                if let Some((gain, offset)) = self.world.sensor_gain(i) {
                    colcos_sim::scenario::individual::apply_sensor_gain(&mut counts, gain, offset);
                }
                counts
            }
            None => self.world.observations()[i].counts,
        }
    }

    /// Robot `i`'s bumper readings in [0, 1] (front-left, front, front-right).
    pub fn bumpers(&self, i: usize) -> [f32; 3] {
        self.world
            .observations()
            .get(i)
            .map(|o| o.bumpers)
            .unwrap_or_default()
    }
}
