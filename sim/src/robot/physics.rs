//! The physics of one arena: walls and robot discs, driven by velocity.
//!
//! Robots are discs seen from above. Every step each robot is driven with its body velocity
//! (`forward * heading`, yaw rate), contacts push discs apart and keep them off the walls, and as a
//! last guard every disc centre is clamped into `[r, w - r] x [r, h - r]`, so no robot ever leaves
//! the arena. Two interchangeable solvers ([`PhysicsBackend`]):
//!
//! - [`PhysicsBackend::Rapier`] (the default): rapier2d dynamic discs (no gravity, low friction) in
//!   four thick static wall boxes; one rapier step per call. Full rigid-body contact dynamics.
//! - [`PhysicsBackend::Discs`]: a purpose-built position solver for equal discs: move, then a few
//!   Gauss-Seidel passes that separate overlapping pairs (found with a uniform grid) and clamp to the
//!   walls. Several times faster than rapier for large swarms (10,000 robots), with the same
//!   guarantees (inside the arena, small overlaps) but no momentum exchange.
//!
//! Both are single-threaded and deterministic: the same inputs give bit-identical poses.
use super::{ColiasParams, Pose, obstacle_contacts};
use crate::arena::Obstacles;
use crate::sensors::NeighbourIndex;
use glam::Vec2;
use rapier2d::prelude::{
    ColliderBuilder, IntegrationParameters, PhysicsWorld, RigidBodyBuilder, RigidBodyHandle,
    Rotation, SpringCoefficients, Vector,
};
use serde::{Deserialize, Serialize};
use std::sync::Arc;

/// Half-thickness of the wall boxes, m: thick enough that nothing can tunnel through.
const WALL_HALF_THICKNESS: f32 = 0.5;
/// Friction coefficient of robots and walls (low: plastic shells sliding past each other).
const FRICTION: f32 = 0.05;
/// rapier's length unit, m: scales its slop (0.005 units = 1 mm) and corrective velocity (0.6 m/s)
/// to the 2 cm robots.
const LENGTH_UNIT: f32 = 0.2;
/// Distance at which rapier starts predictive contacts, m. It must exceed the distance two robots
/// close in one step (2 x 0.35 m/s x 20 ms = 14 mm), or robots meeting head-on overlap by up to that.
const PREDICTION_DISTANCE: f32 = 0.02;
/// Natural frequency of the contact springs, Hz (rapier's default is 30 Hz for dynamic pairs and
/// 60 Hz against fixed bodies). With 20 ms steps those let a line of robots pushed into a wall
/// compress by centimetres; 300 Hz keeps overlaps under half a millimetre.
const CONTACT_FREQUENCY: f32 = 300.0;
/// Most separation passes of the disc solver per step (it stops once no pair overlaps by more than
/// [`DISC_TOLERANCE`]; in free space one pass, in a pile pushed into a wall a few dozen).
const DISC_MAX_PASSES: usize = 64;
/// Overlap the disc solver leaves alone, m.
const DISC_TOLERANCE: f32 = 2e-4;

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

struct RapierState {
    world: PhysicsWorld,
    bodies: Vec<RigidBodyHandle>,
}

#[derive(Default)]
struct DiscState {
    index: NeighbourIndex,
    positions: Vec<Vec2>,
    /// Robots to visit in this pass, and those to visit in the next.
    active: Vec<u32>,
    next: Vec<u32>,
    /// Last pass in which each robot was queued for the next.
    stamp: Vec<u32>,
}

enum Solver {
    Rapier(Box<RapierState>),
    Discs(DiscState),
}

pub struct ArenaPhysics {
    solver: Solver,
    poses: Vec<Pose>,
    size: Vec2,
    radius: f32,
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
            physics.solver = Solver::Rapier(Box::new(RapierState::new(
                size,
                params,
                radius,
                &physics.poses,
            )));
        }
        physics
    }

    /// Adds the arena's static obstacles: robots collide with them (fixed rapier colliders, or the
    /// disc solver's push-out). Call once, before the first step.
    pub fn set_obstacles(&mut self, obstacles: Arc<Obstacles>) {
        if let Solver::Rapier(state) = &mut self.solver {
            obstacle_contacts::add_colliders(&mut state.world, &obstacles, FRICTION);
        }
        self.obstacles = obstacles;
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
        if dt.is_nan() || dt <= 0.0 {
            return;
        }
        let velocity = |i: usize| {
            let (forward, yaw) = velocities.get(i).copied().unwrap_or((0.0, 0.0));
            (
                if forward.is_finite() { forward } else { 0.0 },
                if yaw.is_finite() { yaw } else { 0.0 },
            )
        };
        let (lo, hi) = self.bounds();
        match &mut self.solver {
            Solver::Rapier(state) => state.step(&mut self.poses, velocity, dt, lo, hi),
            Solver::Discs(state) => {
                state.step(
                    &mut self.poses,
                    velocity,
                    dt,
                    lo,
                    hi,
                    self.radius,
                    self.size,
                );
                obstacle_contacts::push_out(&mut self.poses, self.radius, &self.obstacles, lo, hi);
            }
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
            let body = &mut state.world.bodies[state.bodies[i]];
            body.set_translation(p, true);
            body.set_rotation(Rotation::new(heading), true);
            body.set_linvel(Vec2::ZERO, true);
            body.set_angvel(0.0, true);
        }
        self.poses[i] = Pose { pos: p, heading };
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

impl RapierState {
    fn new(size: Vec2, params: &ColiasParams, radius: f32, poses: &[Pose]) -> Self {
        let mut world = PhysicsWorld::new();
        world.gravity = Vector::ZERO;
        world.integration_parameters = IntegrationParameters {
            length_unit: LENGTH_UNIT,
            num_solver_iterations: 4,
            normalized_prediction_distance: PREDICTION_DISTANCE / LENGTH_UNIT,
            contact_softness: SpringCoefficients::new(CONTACT_FREQUENCY, 10.0),
            static_contact_softness: SpringCoefficients::new(CONTACT_FREQUENCY, 10.0),
            ..IntegrationParameters::default()
        };
        let (w, h) = (size.x, size.y);
        let t = WALL_HALF_THICKNESS;
        // Left, right, bottom, top; the horizontal ones span the corners too.
        let walls = [
            (Vec2::new(-t, 0.5 * h), Vec2::new(t, 0.5 * h + 2.0 * t)),
            (Vec2::new(w + t, 0.5 * h), Vec2::new(t, 0.5 * h + 2.0 * t)),
            (Vec2::new(0.5 * w, -t), Vec2::new(0.5 * w + 2.0 * t, t)),
            (Vec2::new(0.5 * w, h + t), Vec2::new(0.5 * w + 2.0 * t, t)),
        ];
        for (centre, half) in walls {
            world.insert(
                RigidBodyBuilder::fixed().translation(centre),
                ColliderBuilder::cuboid(half.x, half.y)
                    .friction(FRICTION)
                    .restitution(0.0),
            );
        }
        let mut bodies = Vec::with_capacity(poses.len());
        for pose in poses {
            let (body, _) = world.insert(
                RigidBodyBuilder::dynamic()
                    .translation(pose.pos)
                    .rotation(pose.heading)
                    .can_sleep(false),
                ColliderBuilder::ball(radius)
                    .mass(params.mass.max(1e-6))
                    .friction(FRICTION)
                    .restitution(0.0),
            );
            bodies.push(body);
        }
        RapierState { world, bodies }
    }

    fn step(
        &mut self,
        poses: &mut [Pose],
        velocity: impl Fn(usize) -> (f32, f32),
        dt: f32,
        lo: Vec2,
        hi: Vec2,
    ) {
        self.world.integration_parameters.dt = dt;
        for (i, &handle) in self.bodies.iter().enumerate() {
            let (forward, yaw) = velocity(i);
            let body = &mut self.world.bodies[handle];
            let dir = Vec2::from_angle(body.rotation().angle());
            body.set_linvel(dir * forward, true);
            body.set_angvel(yaw, true);
        }
        self.world.step();
        for (i, &handle) in self.bodies.iter().enumerate() {
            let body = &mut self.world.bodies[handle];
            let p = body.translation();
            let heading = body.rotation().angle();
            let q = p.clamp(lo, hi);
            if q != p || !q.is_finite() {
                // The last guard: put it back inside and stop it.
                let q = if q.is_finite() { q } else { poses[i].pos };
                body.set_translation(q, false);
                body.set_linvel(Vec2::ZERO, false);
                poses[i] = Pose { pos: q, heading };
            } else {
                poses[i] = Pose { pos: p, heading };
            }
        }
    }
}

impl DiscState {
    #[allow(clippy::too_many_arguments)]
    fn step(
        &mut self,
        poses: &mut [Pose],
        velocity: impl Fn(usize) -> (f32, f32),
        dt: f32,
        lo: Vec2,
        hi: Vec2,
        radius: f32,
        size: Vec2,
    ) {
        // Move: along the heading at the start of the step (as rapier does), then turn.
        self.positions.clear();
        for (i, pose) in poses.iter_mut().enumerate() {
            let (forward, yaw) = velocity(i);
            let p = (pose.pos + pose.forward() * (forward * dt)).clamp(lo, hi);
            pose.heading = wrap_angle(pose.heading + yaw * dt);
            self.positions.push(p);
        }
        // Separate: Gauss-Seidel passes over overlapping pairs, in index order (deterministic). The
        // grid is built once per step; the slack covers the small moves of the passes.
        let contact = 2.0 * radius;
        let slack = 0.5 * radius;
        self.index.rebuild(size, contact + slack, &self.positions);
        let reach = contact + slack;
        // The first pass visits every robot; later passes only those touched by an overlap in the
        // pass before, so a pile somewhere costs only its own robots.
        let n = self.positions.len();
        self.active.clear();
        self.active.extend(0..n as u32);
        self.stamp.clear();
        self.stamp.resize(n, u32::MAX);
        for pass in 0..DISC_MAX_PASSES {
            let mut worst = 0.0f32;
            self.next.clear();
            for k in 0..self.active.len() {
                // Alternate the sweep direction: pushes travel down a line of robots both ways.
                let i = if pass % 2 == 0 {
                    self.active[k]
                } else {
                    self.active[self.active.len() - 1 - k]
                } as usize;
                let positions = &mut self.positions;
                let (stamp, next) = (&mut self.stamp, &mut self.next);
                self.index.for_each_near(positions[i], reach, |j| {
                    if j == i {
                        return;
                    }
                    let d = positions[j] - positions[i];
                    let dist2 = d.length_squared();
                    if dist2 >= contact * contact {
                        return;
                    }
                    let dist = dist2.sqrt();
                    worst = worst.max(contact - dist);
                    // Coincident centres: split along a direction fixed by the indices.
                    let (a, b) = (i.min(j), i.max(j));
                    let n = if dist > 1e-9 {
                        d / dist
                    } else {
                        let u = Vec2::from_angle(a as f32 * 2.399_963 + b as f32);
                        if i == a { u } else { -u }
                    };
                    let push = 0.5 * (contact - dist) * n;
                    positions[i] = (positions[i] - push).clamp(lo, hi);
                    positions[j] = (positions[j] + push).clamp(lo, hi);
                    for m in [i, j] {
                        if stamp[m] != pass as u32 {
                            stamp[m] = pass as u32;
                            next.push(m as u32);
                        }
                    }
                });
            }
            if worst <= DISC_TOLERANCE {
                break;
            }
            // Index order keeps the sweeps deterministic and cache-friendly.
            self.next.sort_unstable();
            std::mem::swap(&mut self.active, &mut self.next);
        }
        for (pose, &p) in poses.iter_mut().zip(&self.positions) {
            pose.pos = p;
        }
    }
}

/// Angle in (-pi, pi], as rapier reports headings.
fn wrap_angle(a: f32) -> f32 {
    use std::f32::consts::{PI, TAU};
    if !a.is_finite() {
        return 0.0;
    }
    let w = (a + PI).rem_euclid(TAU) - PI;
    if w <= -PI { w + TAU } else { w }
}
