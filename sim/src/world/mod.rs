//! A world: one arena with its pheromones, screen, robots, tracker and behaviours, stepped together
//! (design.md, "Data flow of one step").

mod build;
mod inject;
mod placement;
mod step;

use crate::behaviour::{Behaviour, Observation, WheelCommand};
use crate::field::{Kernel, Pheromone};
use crate::rng::SimRng;
use crate::robot::{ArenaPhysics, ColiasParams, DriveState, Pose};
use crate::scenario::{InjectAt, Scenario};
use crate::screen::ScreenSpec;
use crate::sensors::{BumperParams, BumperRays, ColourSensor, NeighbourIndex};
use crate::tracker::{TrackedPose, Tracker};
use glam::Vec2;

/// Per-robot state that the world keeps apart from physics.
pub struct RobotSlot {
    /// Index of the scenario's robot group this robot comes from.
    pub group: usize,
    pub behaviour: Box<dyn Behaviour>,
    /// This robot's own random stream (sensor noise, behaviour choices).
    pub rng: SimRng,
    pub drive: DriveState,
    /// Command applied in the last step.
    pub command: WheelCommand,
}

/// A trail deposit rule of one robot.
struct Deposit {
    robot: usize,
    pheromone: usize,
    kernel: Kernel,
    /// Units per second at the kernel's peak.
    rate: f32,
}

/// A Gaussian source attached to one robot.
struct Emitter {
    robot: usize,
    pheromone: usize,
    /// Index of the source in the pheromone's [`crate::field::GaussianField`].
    source: usize,
    /// `None`: follow always; `Some((targets, distance))`: refresh when near one of `targets`.
    near: Option<(Vec<usize>, f32)>,
}

pub struct World {
    scenario: Scenario,
    time: f32,
    tick: u64,
    dt: f32,
    arena: Vec2,
    robot_params: ColiasParams,
    bumper_params: BumperParams,
    bumper_rays: BumperRays,
    screen: ScreenSpec,
    inject_at: InjectAt,
    pheromones: Vec<Pheromone>,
    physics: ArenaPhysics,
    robots: Vec<RobotSlot>,
    observations: Vec<Observation>,
    tracker: Tracker,
    tracker_rng: SimRng,
    tracked: Vec<TrackedPose>,
    /// Where each robot injected last (None before its first tracked pose).
    last_injection: Vec<Option<Vec2>>,
    /// Scratch: this step's trail segments.
    segments: Vec<inject::Segment>,
    /// Scratch: for each band of rows of each grid field (in field order), the indices of the segments
    /// that may reach it (see `inject`).
    band_segments: Vec<Vec<u32>>,
    neighbours: NeighbourIndex,
    sensor: ColourSensor,
    deposits: Vec<Deposit>,
    emitters: Vec<Emitter>,
    // Scratch buffers reused every step (no per-step allocation).
    velocities: Vec<(f32, f32)>,
    positions: Vec<Vec2>,
    /// Scratch: the four sensor positions of every robot, refreshed by each observation.
    sensor_points: Vec<[Vec2; 4]>,
    /// Scratch: the Gaussian sources frozen at the time of the current observation.
    frozen: crate::field::FrozenSources,
    /// Steps the pheromones instead of the CPU when set (e.g. the GPU backend of `colcos-gpu`).
    field_backend: Option<Box<dyn crate::field::FieldBackend>>,
}

impl World {
    /// Simulation time, s.
    pub fn time(&self) -> f32 {
        self.time
    }
    /// Number of steps taken.
    pub fn tick(&self) -> u64 {
        self.tick
    }
    pub fn dt(&self) -> f32 {
        self.dt
    }
    pub fn scenario(&self) -> &Scenario {
        &self.scenario
    }
    /// Arena size, m.
    pub fn arena(&self) -> Vec2 {
        self.arena
    }
    pub fn screen(&self) -> &ScreenSpec {
        &self.screen
    }
    pub fn pheromones(&self) -> &[Pheromone] {
        &self.pheromones
    }
    pub fn pheromones_mut(&mut self) -> &mut [Pheromone] {
        &mut self.pheromones
    }
    pub fn robot_count(&self) -> usize {
        self.robots.len()
    }
    pub fn robots(&self) -> &[RobotSlot] {
        &self.robots
    }
    pub fn robot_params(&self) -> &ColiasParams {
        &self.robot_params
    }
    /// True poses.
    pub fn poses(&self) -> &[Pose] {
        self.physics.poses()
    }
    /// Poses as the tracker last delivered them.
    pub fn tracked(&self) -> &[TrackedPose] {
        &self.tracked
    }
    /// What each robot senses now.
    pub fn observations(&self) -> &[Observation] {
        &self.observations
    }
    /// Role of robot `i` (its group's `role`).
    pub fn role(&self, i: usize) -> &str {
        &self.scenario.spec.robots[self.robots[i].group].role
    }
    /// Pheromone `index`'s value at `p` as of the current observations: the same value as
    /// [`Pheromone::value_at`] then, with Gaussian sources as frozen once for this step's sensing (a
    /// task's reward reads the field at many points without recomputing each source's time factors).
    pub fn pheromone_value_observed(&self, index: usize, p: Vec2) -> f32 {
        match &self.pheromones[index].model {
            crate::field::FieldModel::Grid(g) => g.value_at(p),
            // Sources that have not started are left out of the frozen set; they add 0.0.
            crate::field::FieldModel::Gaussian(_) => self
                .frozen
                .of(index)
                .iter()
                .fold(0.0, |sum, s| sum + s.value_at(p)),
        }
    }
    /// [`World::pheromone_value_observed`] and its gradient at `p` (per m): analytic for Gaussian
    /// sources (one `exp` per source), central differences `step` m apart on a grid.
    pub fn pheromone_value_and_gradient_observed(
        &self,
        index: usize,
        p: Vec2,
        step: f32,
    ) -> (f32, Vec2) {
        match &self.pheromones[index].model {
            crate::field::FieldModel::Grid(g) => {
                let (hx, hy) = (Vec2::X * step, Vec2::Y * step);
                let inv = 1.0 / (2.0 * step);
                let grad = Vec2::new(
                    g.value_at(p + hx) - g.value_at(p - hx),
                    g.value_at(p + hy) - g.value_at(p - hy),
                ) * inv;
                (g.value_at(p), grad)
            }
            crate::field::FieldModel::Gaussian(_) => {
                self.frozen
                    .of(index)
                    .iter()
                    .fold((0.0, Vec2::ZERO), |(value, grad), s| {
                        let (v, g) = s.value_and_gradient(p);
                        (value + v, grad + g)
                    })
            }
        }
    }
    /// The colour sensor model shared by all robots.
    pub fn sensor(&self) -> &ColourSensor {
        &self.sensor
    }
    /// Installs a field backend that steps the pheromones from now on (`None`: the CPU).
    pub fn set_field_backend(&mut self, backend: Option<Box<dyn crate::field::FieldBackend>>) {
        self.field_backend = backend;
    }
    /// The installed field backend's description, or `None` for the CPU.
    pub fn field_backend(&self) -> Option<String> {
        self.field_backend.as_ref().map(|b| b.describe())
    }
    /// Steps until the scenario's duration is reached.
    pub fn is_finished(&self) -> bool {
        self.tick >= self.scenario.steps()
    }
}
