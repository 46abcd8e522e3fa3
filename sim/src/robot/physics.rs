//! rapier2d world of one arena: walls and robot discs, driven by velocity.
//!
//! Robots are dynamic discs seen from above (no gravity, little friction). Every step each disc's
//! linear velocity is set to `forward * heading` and its angular velocity to the yaw rate, then rapier
//! takes one step and its contact solver pushes discs apart and keeps them off the walls. The walls are
//! four thick static boxes just outside `[0, w] x [0, h]`. As a last guard every disc centre is
//! clamped into `[r, w - r] x [r, h - r]` after the step, so no robot ever leaves the arena.
//!
//! rapier is run single-threaded (its `parallel` feature is off), so the same inputs give
//! bit-identical poses.
use super::{ColiasParams, Pose};
use glam::Vec2;
use rapier2d::prelude::{
    ColliderBuilder, IntegrationParameters, SpringCoefficients, PhysicsWorld, RigidBodyBuilder, RigidBodyHandle, Rotation, Vector,
};

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

pub struct ArenaPhysics {
    world: PhysicsWorld,
    bodies: Vec<RigidBodyHandle>,
    poses: Vec<Pose>,
    size: Vec2,
    radius: f32,
}

impl ArenaPhysics {
    /// An arena of `size` (m) with walls, and one robot at each pose.
    pub fn new(size: Vec2, params: &ColiasParams, poses: &[Pose]) -> Self {
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
        let (w, h) = (size.x.max(0.0), size.y.max(0.0));
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
                ColliderBuilder::cuboid(half.x, half.y).friction(FRICTION).restitution(0.0),
            );
        }
        let radius = params.radius.max(1e-4);
        let mut physics = ArenaPhysics { world, bodies: Vec::with_capacity(poses.len()), poses: Vec::new(), size, radius };
        for pose in poses {
            let p = physics.clamp_position(pose.pos);
            let (body, _) = physics.world.insert(
                RigidBodyBuilder::dynamic().translation(p).rotation(pose.heading).can_sleep(false),
                ColliderBuilder::ball(radius).mass(params.mass.max(1e-6)).friction(FRICTION).restitution(0.0),
            );
            physics.bodies.push(body);
            physics.poses.push(Pose { pos: p, heading: pose.heading });
        }
        physics
    }

    /// Drives every robot with its body velocity (forward m/s, yaw rate rad/s) for `dt`, resolving
    /// contacts with walls and each other. Robots without an entry in `velocities` (or with a
    /// non-finite one) are commanded to stand still.
    pub fn step(&mut self, velocities: &[(f32, f32)], dt: f32) {
        if !(dt > 0.0) {
            return;
        }
        self.world.integration_parameters.dt = dt;
        for (i, &handle) in self.bodies.iter().enumerate() {
            let (forward, yaw) = velocities.get(i).copied().unwrap_or((0.0, 0.0));
            let forward = if forward.is_finite() { forward } else { 0.0 };
            let yaw = if yaw.is_finite() { yaw } else { 0.0 };
            let body = &mut self.world.bodies[handle];
            let dir = Vec2::from_angle(body.rotation().angle());
            body.set_linvel(dir * forward, true);
            body.set_angvel(yaw, true);
        }
        self.world.step();
        let (lo, hi) = self.bounds();
        for (i, &handle) in self.bodies.iter().enumerate() {
            let body = &mut self.world.bodies[handle];
            let p = body.translation();
            let heading = body.rotation().angle();
            let q = p.clamp(lo, hi);
            if q != p || !q.is_finite() {
                let q = if q.is_finite() { q } else { self.poses[i].pos };
                body.set_translation(q, false);
                // The wall has stopped it: drop the velocity component that pushed it out.
                body.set_linvel(Vec2::ZERO, false);
                self.poses[i] = Pose { pos: q, heading };
            } else {
                self.poses[i] = Pose { pos: p, heading };
            }
        }
    }

    /// True poses after the last step.
    pub fn poses(&self) -> &[Pose] {
        &self.poses
    }

    /// Number of robots.
    pub fn len(&self) -> usize {
        self.bodies.len()
    }

    /// True when the arena has no robots.
    pub fn is_empty(&self) -> bool {
        self.bodies.is_empty()
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
        let body = &mut self.world.bodies[self.bodies[i]];
        body.set_translation(p, true);
        body.set_rotation(Rotation::new(pose.heading), true);
        body.set_linvel(Vec2::ZERO, true);
        body.set_angvel(0.0, true);
        self.poses[i] = Pose { pos: p, heading: pose.heading };
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
        if p.is_finite() { p.clamp(lo, hi) } else { 0.5 * (lo + hi) }
    }
}

