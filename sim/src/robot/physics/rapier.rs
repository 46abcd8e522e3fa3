//! The rapier2d solver: dynamic discs driven by velocity in four thick static wall boxes.
use super::FRICTION;
use crate::robot::{ColiasParams, Pose};
use glam::Vec2;
use rapier2d::prelude::{
    ColliderBuilder, IntegrationParameters, PhysicsWorld, RigidBodyBuilder, RigidBodyHandle,
    Rotation, SpringCoefficients, Vector,
};

/// Half-thickness of the wall boxes, m: thick enough that nothing can tunnel through.
const WALL_HALF_THICKNESS: f32 = 0.5;
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

pub(super) struct RapierState {
    pub(super) world: PhysicsWorld,
    pub(super) bodies: Vec<RigidBodyHandle>,
}

impl RapierState {
    pub(super) fn new(size: Vec2, params: &ColiasParams, radius: f32, poses: &[Pose]) -> Self {
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

    pub(super) fn step(
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

    /// Teleports body `i` to `p`, `heading` at rest.
    pub(super) fn set_pose(&mut self, i: usize, p: Vec2, heading: f32) {
        let body = &mut self.world.bodies[self.bodies[i]];
        body.set_translation(p, true);
        body.set_rotation(Rotation::new(heading), true);
        body.set_linvel(Vec2::ZERO, true);
        body.set_angvel(0.0, true);
    }
}
