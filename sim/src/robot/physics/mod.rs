//! The physics of one arena: walls and robot discs, driven by velocity.
//!
//! Robots are discs seen from above. Every step each robot is driven with its body velocity
//! (`forward * heading`, yaw rate), contacts push discs apart and keep them off the walls, and as a
//! last guard every disc centre is clamped into `[r, w - r] x [r, h - r]`, so no robot ever leaves
//! the arena. Two interchangeable solvers ([`PhysicsBackend`]):
//!
//! - [`PhysicsBackend::Rapier`] (the default): rapier2d dynamic discs (no gravity, low friction) in
//!   four thick static wall boxes; one rapier step per call. Full rigid-body contact dynamics. A step
//!   in which no contact is possible moves the discs without rapier's pipeline, bit-identically.
//! - [`PhysicsBackend::Discs`]: a purpose-built position solver for equal discs: move, then a few
//!   Gauss-Seidel passes that separate overlapping pairs (found with a uniform grid) and clamp to the
//!   walls. Several times faster than rapier for large swarms (10,000 robots), with the same
//!   guarantees (inside the arena, small overlaps) but no momentum exchange.
//!
//! Both are single-threaded and deterministic: the same inputs give bit-identical poses. Many small
//! rapier arenas can share one rapier world, a [`RapierHost`], and take their contact steps together.
mod discs;
mod rapier;
mod rapier_host;

use super::{ColiasParams, Pose, obstacle_contacts};
use crate::arena::Obstacles;
use discs::DiscState;
use glam::Vec2;
use rapier::RapierState;
pub use rapier_host::{MAX_HOSTED_ARENAS, RapierHost};
use serde::{Deserialize, Serialize};
use std::sync::Arc;

/// Friction coefficient of robots and walls (low: plastic shells sliding past each other).
const FRICTION: f32 = 0.05;

/// Which solver moves the robots.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PhysicsBackend {
    /// rapier2d rigid bodies.
    #[default]
    Rapier,
    /// The fast position-based disc solver.
    Discs,
}

enum Solver {
    Rapier(RapierState),
    Discs(DiscState),
}

/// One step as the solvers take it: its length `dt`, where the disc centres may be (`lo..hi`, the
/// last guard of every step) and the discs' radius.
#[derive(Clone, Copy)]
struct Step {
    dt: f32,
    lo: Vec2,
    hi: Vec2,
    radius: f32,
}

pub struct ArenaPhysics {
    solver: Solver,
    poses: Vec<Pose>,
    size: Vec2,
    radius: f32,
    /// Each robot's mass, kg.
    mass: f32,
    /// Static obstacles (none unless [`ArenaPhysics::set_obstacles`] gave some).
    obstacles: Arc<Obstacles>,
}

impl ArenaPhysics {
    /// An arena of `size` (m) with walls, and one robot at each pose (rapier backend).
    pub fn new(size: Vec2, params: &ColiasParams, poses: &[Pose]) -> Self {
        Self::with_backend(size, params, poses, PhysicsBackend::Rapier)
    }

    /// An arena of `size` (m) with walls, and one robot at each pose, moved by `backend`.
    pub fn with_backend(
        size: Vec2,
        params: &ColiasParams,
        poses: &[Pose],
        backend: PhysicsBackend,
    ) -> Self {
        let radius = params.radius.max(1e-4);
        let size = size.max(Vec2::ZERO);
        let mut physics = ArenaPhysics {
            solver: Solver::Discs(DiscState::default()),
            poses: Vec::with_capacity(poses.len()),
            size,
            radius,
            mass: params.mass,
            obstacles: Arc::default(),
        };
        for pose in poses {
            let p = physics.clamp_position(pose.pos);
            physics.poses.push(Pose {
                pos: p,
                heading: pose.heading,
            });
        }
        if backend == PhysicsBackend::Rapier {
            physics.solver = Solver::Rapier(RapierState::new(
                size,
                params.mass,
                radius,
                &physics.poses,
                &Obstacles::default(),
            ));
        }
        physics
    }

    /// Adds the arena's static obstacles: robots collide with them (fixed rapier colliders, or the
    /// disc solver's push-out). Call once, before the first step.
    pub fn set_obstacles(&mut self, obstacles: Arc<Obstacles>) {
        if let Solver::Rapier(state) = &mut self.solver {
            // Rebuilt, so that the obstacles come before the robots in rapier's order.
            let free_steps = state.free_steps;
            *state = RapierState::new(self.size, self.mass, self.radius, &self.poses, &obstacles);
            state.free_steps = free_steps;
        }
        self.obstacles = obstacles;
    }

    /// Whether the rapier solver may take a step in which no contact is possible without its
    /// pipeline (on by default; the result is bit-identical, this switch is there to test that).
    /// No effect on the disc solver.
    pub fn set_free_steps(&mut self, on: bool) {
        if let Solver::Rapier(state) = &mut self.solver {
            state.free_steps = on;
        }
    }

    /// The solver in use.
    pub fn backend(&self) -> PhysicsBackend {
        match self.solver {
            Solver::Rapier(_) => PhysicsBackend::Rapier,
            Solver::Discs(_) => PhysicsBackend::Discs,
        }
    }

    /// Drives every robot with its body velocity (forward m/s, yaw rate rad/s) for `dt`, resolving
    /// contacts with walls and each other. Robots without an entry in `velocities` (or with a
    /// non-finite one) are commanded to stand still.
    pub fn step(&mut self, velocities: &[(f32, f32)], dt: f32) {
        self.step_facing(velocities, dt, |_, heading| Vec2::from_angle(heading));
    }

    /// [`Self::step`] where `forward(i, heading)` gives robot `i`'s heading vector at `heading` (a
    /// world passes the ones its sensing already computed; they must equal `Vec2::from_angle`).
    pub fn step_facing(
        &mut self,
        velocities: &[(f32, f32)],
        dt: f32,
        forward: impl Fn(usize, f32) -> Vec2,
    ) {
        if dt.is_nan() || dt <= 0.0 {
            return;
        }
        let velocity = |i: usize| velocity_of(velocities, i);
        let step = self.step_of(dt);
        match &mut self.solver {
            Solver::Rapier(state) => state.step(&mut self.poses, velocity, step, &self.obstacles),
            Solver::Discs(state) => {
                state.step(&mut self.poses, velocity, forward, step, self.size);
                let Step { lo, hi, radius, .. } = step;
                obstacle_contacts::push_out(&mut self.poses, radius, &self.obstacles, lo, hi);
            }
        }
    }

    /// Moves this arena's rapier steps into slot `slot` of `host` (see [`RapierHost`]). Returns
    /// false, and changes nothing, for the disc solver, an arena of another size or with other
    /// obstacles than the host's, or a slot the host does not have.
    pub fn attach(&mut self, host: &mut RapierHost, slot: usize) -> bool {
        let size = self.size.max(Vec2::ZERO);
        if !host.fits(size, &self.obstacles) {
            return false;
        }
        match &mut self.solver {
            Solver::Rapier(state) => state.attach(host, slot, self.radius, self.mass),
            Solver::Discs(_) => false,
        }
    }

    /// The first half of a step in `host`: like [`Self::step`] for an arena that is not attached to
    /// it (or uses the disc solver); else the arena's poses are final only after
    /// [`RapierHost::step`] and [`Self::finish_in`].
    pub fn step_in(&mut self, host: &mut RapierHost, velocities: &[(f32, f32)], dt: f32) {
        if !matches!(self.solver, Solver::Rapier(_)) {
            return self.step(velocities, dt);
        }
        if dt.is_nan() || dt <= 0.0 {
            return;
        }
        let step = self.step_of(dt);
        let Solver::Rapier(state) = &mut self.solver else {
            return;
        };
        let velocity = |i: usize| velocity_of(velocities, i);
        state.step_in(host, &mut self.poses, velocity, step, &self.obstacles);
    }

    /// The second half of a step in `host` (after [`RapierHost::step`]).
    pub fn finish_in(&mut self, host: &mut RapierHost) {
        // Only the step's guard is left to apply: its time was taken in `step_in`.
        let step = self.step_of(0.0);
        if let Solver::Rapier(state) = &mut self.solver {
            state.finish_in(host, &mut self.poses, step);
        }
    }

    /// True poses after the last step.
    pub fn poses(&self) -> &[Pose] {
        &self.poses
    }

    /// Number of robots.
    pub fn len(&self) -> usize {
        self.poses.len()
    }

    /// True when the arena has no robots.
    pub fn is_empty(&self) -> bool {
        self.poses.is_empty()
    }

    /// Arena size, m.
    pub fn size(&self) -> Vec2 {
        self.size
    }

    /// Robot radius, m.
    pub fn radius(&self) -> f32 {
        self.radius
    }

    /// Teleports robot `i` to `pose` (clamped into the arena) at rest, e.g. for a reset.
    pub fn set_pose(&mut self, i: usize, pose: Pose) {
        let p = self.clamp_position(pose.pos);
        let heading = if pose.heading.is_finite() {
            pose.heading
        } else {
            0.0
        };
        if let Solver::Rapier(state) = &mut self.solver {
            state.set_pose(i, p, heading);
        }
        self.poses[i] = Pose { pos: p, heading };
    }

    /// A step of `dt` in this arena.
    fn step_of(&self, dt: f32) -> Step {
        let (lo, hi) = self.bounds();
        Step {
            dt,
            lo,
            hi,
            radius: self.radius,
        }
    }

    /// Where disc centres may be.
    fn bounds(&self) -> (Vec2, Vec2) {
        let r = Vec2::splat(self.radius);
        let lo = r.min(self.size * 0.5);
        let hi = (self.size - r).max(lo);
        (lo, hi)
    }

    fn clamp_position(&self, p: Vec2) -> Vec2 {
        let (lo, hi) = self.bounds();
        if p.is_finite() {
            p.clamp(lo, hi)
        } else {
            0.5 * (lo + hi)
        }
    }
}

/// Robot `i`'s body velocity (forward, yaw rate): a stop when missing or not finite.
fn velocity_of(velocities: &[(f32, f32)], i: usize) -> (f32, f32) {
    let (forward, yaw) = velocities.get(i).copied().unwrap_or((0.0, 0.0));
    (
        if forward.is_finite() { forward } else { 0.0 },
        if yaw.is_finite() { yaw } else { 0.0 },
    )
}
