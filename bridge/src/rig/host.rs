//! The host's side of one rig tick: the simulator's own injection, field, screen and sensing stages,
//! run with the real arena: poses from a tracker in place of physics and the tracker model, and the
//! robots' behaviours deciding the wheel commands that go out over the link.
use colcos_sim::behaviour::{Observation, WheelCommand};
use colcos_sim::error::Result;
use colcos_sim::robot::ColiasParams;
use colcos_sim::robot::Pose;
use colcos_sim::scenario::{Scenario, SensorSource as SensorMode};
use colcos_sim::screen::ScreenSpec;
use colcos_sim::tracker::TrackedPose;
use colcos_sim::world::{ArenaView, RobotSlot, WorldParts, stages};
use glam::Vec2;
use image::RgbImage;

/// The data sets of a world without bodies or a tracker model, stepped tick by tick.
pub struct HostWorld {
    screen: ScreenSpec,
    parts: WorldParts,
    /// Host time, s: the sum of the ticks' measured durations.
    time: f32,
    ticks: u64,
    /// Latest tracked pose of every robot (`seen` false until the tracker has reported it).
    tracked: Vec<TrackedPose>,
    /// Scratch: the poses injection and sensing use this tick, and as tracked poses.
    poses: Vec<Pose>,
    predicted: Vec<TrackedPose>,
    /// Scratch: the robots' own readings, kept across virtual sensing in [`SensorMode::Robot`].
    kept: Vec<Observation>,
    commands: Vec<WheelCommand>,
    mode: SensorMode,
    /// Each pose is predicted forward by this much (s) from the robot's last command before pheromone
    /// is injected or sensed there: the tracker's pose is this old when it is used.
    latency: f32,
    /// The robots' parameters (the wheel base for the prediction, the drive's lag and limits).
    params: ColiasParams,
    arena: Vec2,
    /// Each robot's role (its group's).
    roles: Vec<String>,
}

impl HostWorld {
    /// A host for `scenario`: its fields, injection rules, sensing state and behaviours, with no robot
    /// seen yet.
    pub fn new(scenario: &Scenario, mode: SensorMode) -> Result<HostWorld> {
        Self::with_index(scenario, mode, 0)
    }

    /// [`HostWorld::new`] with the random streams of world index `index` (as `World::with_index`).
    pub fn with_index(scenario: &Scenario, mode: SensorMode, index: u64) -> Result<HostWorld> {
        let parts = WorldParts::build(scenario, index)?;
        let n = parts.slots.len();
        Ok(HostWorld {
            screen: scenario.spec.screen,
            time: 0.0,
            ticks: 0,
            tracked: vec![TrackedPose::default(); n],
            poses: vec![Pose::default(); n],
            predicted: vec![TrackedPose::default(); n],
            kept: Vec::with_capacity(n),
            commands: vec![WheelCommand::STOP; n],
            mode,
            latency: 0.0,
            params: scenario.spec.robot,
            arena: scenario.arena_size(),
            roles: (parts.slots.iter())
                .map(|s| scenario.spec.robots[s.group].role.clone())
                .collect(),
            parts,
        })
    }

    pub fn robot_count(&self) -> usize {
        self.tracked.len()
    }
    pub fn time(&self) -> f32 {
        self.time
    }
    pub fn ticks(&self) -> u64 {
        self.ticks
    }
    pub fn screen(&self) -> &ScreenSpec {
        &self.screen
    }
    pub fn mode(&self) -> SensorMode {
        self.mode
    }
    /// Sets the latency compensation, s (clamped to [0, 1]).
    pub fn set_latency(&mut self, latency: f32) {
        self.latency = if latency.is_finite() {
            latency.clamp(0.0, 1.0)
        } else {
            0.0
        };
    }
    /// The tracked poses as last given.
    pub fn tracked(&self) -> &[TrackedPose] {
        &self.tracked
    }
    /// The poses injection and sensing used in the last tick (latency-compensated).
    pub fn poses(&self) -> &[Pose] {
        &self.poses
    }
    pub fn observations(&self) -> &[Observation] {
        self.parts.sensing.observations()
    }
    /// Each robot's group in the scenario.
    pub fn groups(&self) -> Vec<usize> {
        self.parts.slots.iter().map(|s| s.group).collect()
    }
    /// The commands the behaviours decided in the last tick.
    pub fn commands(&self) -> &[WheelCommand] {
        &self.commands
    }
    pub fn pheromones(&self) -> &[colcos_sim::field::Pheromone] {
        self.parts.fields.pheromones()
    }
    pub fn pheromones_mut(&mut self) -> &mut [colcos_sim::field::Pheromone] {
        self.parts.fields.pheromones_mut()
    }
    /// Installs a field backend (`None`: the CPU).
    /// Robot `i`'s deposit actions' fractions, as `World::deposit_actions`.
    pub fn deposit_actions(&self, i: usize) -> &[f32] {
        self.parts.injection.deposit_actions(i)
    }
    /// Chooses how much robot `i` lays of each of its deposit actions from the next tick on, as
    /// `World::set_deposit_actions`: injected at its tracked pose like any trail.
    pub fn set_deposit_actions(&mut self, i: usize, fractions: impl IntoIterator<Item = f32>) {
        self.parts.injection.set_deposit_actions(i, fractions);
    }
    pub fn set_field_backend(&mut self, backend: Option<Box<dyn colcos_sim::field::FieldBackend>>) {
        self.parts.fields.set_backend(backend);
    }

    /// Robot `i` was seen at `pose` (our frame) in a frame captured at host time `stamp`.
    pub fn set_pose(&mut self, i: usize, pose: Pose, stamp: f32) {
        if let Some(t) = self.tracked.get_mut(i)
            && pose.pos.is_finite()
            && pose.heading.is_finite()
        {
            *t = TrackedPose {
                pose,
                stamp,
                seen: true,
            };
        }
    }

    /// Takes over the tracked poses of `from` (a new episode's host on the same arena: the robots are
    /// where the tracker last saw them, as old as they were).
    pub fn adopt_tracking(&mut self, from: &HostWorld) {
        for (mine, theirs) in self.tracked.iter_mut().zip(from.tracked()) {
            if theirs.seen {
                *mine = TrackedPose {
                    stamp: self.time - (from.time - theirs.stamp),
                    ..*theirs
                };
            }
        }
    }

    /// Robot `i`'s own readings (real sensors), in the simulator's sensor order: used by the next
    /// tick's decisions in [`SensorMode::Robot`].
    pub fn set_readings(&mut self, i: usize, counts: [[u16; 3]; 4], bumpers: [f32; 3]) {
        let intensity = self.parts.sensing.sensor().intensities(&counts);
        if let Some(o) = self.parts.sensing.observations_mut().get_mut(i) {
            o.counts = counts;
            o.intensity = intensity;
            o.bumpers = bumpers.map(|b| {
                if b.is_finite() {
                    b.clamp(0.0, 1.0)
                } else {
                    0.0
                }
            });
        }
    }

    /// One tick of `dt` s (the measured time since the last): the fields step, pheromone is injected at
    /// the tracked poses, every robot senses (virtually, or keeps its reported readings) and decides.
    /// Returns the wheel commands, one per robot; a robot never seen gets a stop.
    pub fn tick(&mut self, dt: f32) -> &[WheelCommand] {
        let dt = if dt.is_finite() {
            dt.clamp(0.0, 1.0)
        } else {
            0.0
        };
        self.ticks += 1;
        self.time += dt;
        let wheel_base = self.params.wheel_base;
        let parts = &mut self.parts;
        stages::step_fields(&mut parts.fields, dt, false);
        for ((p, t), cmd) in self.poses.iter_mut().zip(&self.tracked).zip(&self.commands) {
            *p = predict(t.pose, *cmd, self.latency, self.time - t.stamp, wheel_base);
        }
        for ((out, t), p) in self
            .predicted
            .iter_mut()
            .zip(&self.tracked)
            .zip(&self.poses)
        {
            *out = TrackedPose { pose: *p, ..*t };
        }
        stages::inject(
            &mut parts.injection,
            &mut parts.fields,
            &self.poses,
            &self.predicted,
            dt,
        );
        self.kept.clear();
        if self.mode == SensorMode::Robot {
            self.kept.extend_from_slice(parts.sensing.observations());
        }
        stages::index(&mut parts.sensing, &self.poses);
        stages::sense(
            &mut parts.sensing,
            &mut parts.fields,
            &self.screen,
            &self.poses,
            &mut parts.slots,
            self.time,
        );
        if self.mode == SensorMode::Robot {
            for (o, k) in parts.sensing.observations_mut().iter_mut().zip(&self.kept) {
                o.counts = k.counts;
                o.intensity = k.intensity;
                o.bumpers = k.bumpers;
            }
        }
        stages::decide(
            &mut parts.slots,
            parts.sensing.observations(),
            &mut self.commands,
        );
        for (cmd, t) in self.commands.iter_mut().zip(&self.tracked) {
            if !t.seen {
                *cmd = WheelCommand::STOP;
            }
        }
        &self.commands
    }

    /// The commands as sent (after the shield and the stops) drive each robot's model of its wheels
    /// for `dt` s: what [`ArenaView::robots`] shows of the drives, as the simulator's drive stage does.
    pub fn drive(&mut self, sent: &[WheelCommand], dt: f32) {
        for (slot, cmd) in self.parts.slots.iter_mut().zip(sent) {
            slot.drive.update(*cmd, &self.params, dt);
            slot.command = *cmd;
        }
    }

    /// The screen image, eq. (1), drawn into `img` at its size (reusing its buffer).
    pub fn render_into(&self, img: &mut RgbImage) {
        colcos_sim::screen::render_into(self.parts.fields.pheromones(), &self.screen, img);
        // The LCD draws printed obstacles over the pheromones (physical ones it cannot).
        if let Some(printed) = self.parts.sensing.obstacles().printed() {
            printed.paint(img, &self.screen);
        }
    }

    /// The screen image, eq. (1), at `width x height` (the panel's resolution for the LCD).
    pub fn render(&self, width: u32, height: u32) -> RgbImage {
        let mut img = RgbImage::new(width, height);
        self.render_into(&mut img);
        img
    }
}

/// A rig's arena as the loop functions (task rewards, metrics) see it: the tracked poses as used this
/// tick, the robots' observations and drives, the fields.
impl ArenaView for HostWorld {
    fn arena(&self) -> Vec2 {
        self.arena
    }
    fn screen(&self) -> &ScreenSpec {
        &self.screen
    }
    fn robot_params(&self) -> &ColiasParams {
        &self.params
    }
    fn poses(&self) -> &[Pose] {
        &self.poses
    }
    fn obstacles(&self) -> &colcos_sim::arena::Obstacles {
        self.parts.sensing.obstacles()
    }
    fn observations(&self) -> &[Observation] {
        self.parts.sensing.observations()
    }
    fn robots(&self) -> &[RobotSlot] {
        &self.parts.slots
    }
    fn fields(&self) -> &colcos_sim::world::FieldSet {
        &self.parts.fields
    }
    fn role(&self, i: usize) -> &str {
        &self.roles[i]
    }
}

/// Where a robot captured at `pose` `age` s ago will be when pheromone injected now shows on the
/// screen, `latency` s from now: driven on a circular arc by its last wheel command (differential
/// drive, wheels `wheel_base` apart). No prediction without a latency to compensate.
pub(crate) fn predict(
    pose: Pose,
    cmd: WheelCommand,
    latency: f32,
    age: f32,
    wheel_base: f32,
) -> Pose {
    let t = (age.max(0.0) + latency).min(0.5);
    if latency <= 0.0 || !cmd.left.is_finite() || !cmd.right.is_finite() || wheel_base <= 0.0 {
        return pose;
    }
    let v = 0.5 * (cmd.left + cmd.right);
    let w = (cmd.right - cmd.left) / wheel_base;
    let (s, c) = pose.heading.sin_cos();
    let mut p = pose;
    if (w * t).abs() < 1e-6 {
        p.pos.x += v * t * c;
        p.pos.y += v * t * s;
    } else {
        let h = pose.heading + w * t;
        p.pos.x += v / w * (h.sin() - s);
        p.pos.y -= v / w * (h.cos() - c);
        p.heading = h;
    }
    p
}
