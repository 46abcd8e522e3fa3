//! The rapier2d solver: dynamic discs driven by velocity in four thick static wall boxes.
use super::{FRICTION, Step};
use crate::arena::Obstacles;
use crate::robot::Pose;
use glam::Vec2;
use rapier2d::math::Pose as Pose2;
use rapier2d::prelude::{
    CCDSolver, ColliderBuilder, ImpulseJointSet, IntegrationParameters, InteractionGroups,
    MultibodyJointSet, PhysicsPipeline, PhysicsWorld, RigidBody, RigidBodyBuilder, RigidBodyHandle,
    RigidBodySet, Rotation, SoftBodySet, SpringCoefficients, Vector,
};
use std::cell::RefCell;

/// Half-thickness of the wall boxes, m: thick enough that nothing can tunnel through.
const WALL_HALF_THICKNESS: f32 = 0.5;
/// rapier's length unit, m: scales its slop (0.005 units = 1 mm) and corrective velocity (0.6 m/s)
/// to the 2 cm robots.
const LENGTH_UNIT: f32 = 0.2;
/// Distance at which rapier starts predictive contacts, m. It must exceed the distance two robots
/// close in one step (2 x 0.35 m/s x 20 ms = 14 mm), or robots meeting head-on overlap by up to that;
/// no larger, as every pair and wall within it costs a contact and a step through the pipeline.
const PREDICTION_DISTANCE: f32 = 0.015;
/// Natural frequency of the contact springs, Hz (rapier's default is 30 Hz for dynamic pairs and
/// 60 Hz against fixed bodies). With 20 ms steps those let a line of robots pushed into a wall
/// compress by centimetres; 300 Hz keeps overlaps under half a millimetre.
const CONTACT_FREQUENCY: f32 = 300.0;

/// rapier's solver substeps per step (its default). Two would cut a fifth of a contact step's work
/// and still pass the contact tests, but fewer predator-prey encounters raise the alarm in case II
/// (8 runs of 32 without one, against 3 of 32 with four).
const SUBSTEPS: usize = 4;

/// Margin on rapier's prediction distance before a step counts as free of contacts, m.
const FREE_MARGIN: f32 = 0.001;
/// Most robots for which the free-step test checks every pair (a large swarm always has contacts).
const FREE_MAX_ROBOTS: usize = 64;
/// rapier's cap on a body's rotation per step, rad (its solver's `MAX_ROTATION`).
const MAX_ROTATION: f32 = std::f32::consts::FRAC_PI_4;

/// What every arena stepped on a thread can share: rapier's pipeline (only scratch buffers between
/// steps) and the sets an arena of discs leaves empty (joints, soft bodies, CCD), which the pipeline
/// still reads every step. One of each per thread keeps a batch of many small arenas from pulling
/// each arena's own copies into cache: 4-5 % more steps per second at 1,024 arenas.
#[derive(Default)]
struct SharedSets {
    pipeline: PhysicsPipeline,
    impulse_joints: ImpulseJointSet,
    multibody_joints: MultibodyJointSet,
    soft_bodies: SoftBodySet,
    ccd_solver: CCDSolver,
}

thread_local! {
    static SHARED: RefCell<SharedSets> = RefCell::default();
}

/// What an arena living in a [`RapierHost`](super::RapierHost) keeps of it.
pub(super) struct HostedArena {
    pub(super) slot: usize,
    /// The host's bodies lag this arena's mirror (free steps, a teleport, a new episode).
    pub(super) stale: bool,
    /// Its velocities are in the host and its poses will be read back after the host's step.
    pub(super) pending: bool,
}

/// The rapier solver's state. What a free step reads is kept in this small struct, held inline by
/// the arena; the rapier world (several KB of its own) is touched only by full steps.
pub(super) struct RapierState {
    /// Its bodies, colliders, broad and narrow phase and islands; its joint, soft-body and CCD sets
    /// stay empty (steps pass the thread's [`SharedSets`] instead).
    pub(super) world: Box<PhysicsWorld>,
    pub(super) bodies: Vec<RigidBodyHandle>,
    /// Where the arena's full steps run while it lives in a [`RapierHost`](super::RapierHost)
    /// (`world` is then idle).
    pub(super) hosted: Option<HostedArena>,
    /// Each body's pose as rapier holds it (rotation as a unit complex), mirrored here so that a
    /// step in which no contact is possible moves the bodies without a rapier call.
    pub(super) rotations: Vec<Rotation>,
    pub(super) translations: Vec<Vec2>,
    /// Free steps (or a host) moved the mirror since `world`'s bodies were last written.
    pub(super) stale: bool,
    /// Whether free steps are taken (off: every step goes through rapier's pipeline).
    pub(super) free_steps: bool,
    /// Whether the arena has obstacles (set with them).
    pub(super) has_obstacles: bool,
    /// rapier's substeps per step and linear speed cap, m/s (copied from its parameters).
    substeps: usize,
    max_lin: f32,
}

/// A rapier world with this solver's integration parameters, empty.
pub(super) fn empty_world() -> PhysicsWorld {
    let mut world = PhysicsWorld::new();
    world.gravity = Vector::ZERO;
    world.integration_parameters = IntegrationParameters {
        length_unit: LENGTH_UNIT,
        num_solver_iterations: SUBSTEPS,
        normalized_prediction_distance: PREDICTION_DISTANCE / LENGTH_UNIT,
        contact_softness: SpringCoefficients::new(CONTACT_FREQUENCY, 10.0),
        static_contact_softness: SpringCoefficients::new(CONTACT_FREQUENCY, 10.0),
        // Recycling keeps a pair's old contact points until the pair moved 1 cm (rapier's
        // 0.05 length units): half a robot radius of stale contact, and a history that free
        // steps would change. Every pair is recomputed every step instead.
        contact_recycling: false,
        // No CCD: a robot moves at most 7 mm a step, well within the prediction distance.
        max_ccd_substeps: 0,
        ..IntegrationParameters::default()
    };
    world
}

/// Adds the four walls around an arena of `size` to `world`, in collision `groups`.
pub(super) fn add_walls(world: &mut PhysicsWorld, size: Vec2, groups: InteractionGroups) {
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
        // A collider without a body, like the obstacles': it never moves.
        world.insert_collider(
            ColliderBuilder::cuboid(half.x, half.y)
                .translation(centre)
                .friction(FRICTION)
                .restitution(0.0)
                .collision_groups(groups),
            None,
        );
    }
}

/// Adds one robot disc at `pose` to `world`, in collision `groups`.
pub(super) fn add_robot(
    world: &mut PhysicsWorld,
    pose: &Pose,
    radius: f32,
    mass: f32,
    groups: InteractionGroups,
) -> RigidBodyHandle {
    let (body, _) = world.insert(
        RigidBodyBuilder::dynamic()
            .translation(pose.pos)
            .rotation(pose.heading)
            .can_sleep(false),
        ColliderBuilder::ball(radius)
            .mass(mass.max(1e-6))
            .friction(FRICTION)
            .restitution(0.0)
            .collision_groups(groups),
    );
    body
}

/// One pipeline step of `world` by its `integration_parameters.dt`, with this thread's shared sets.
pub(super) fn step_pipeline(w: &mut PhysicsWorld) {
    SHARED.with_borrow_mut(|shared| {
        shared.pipeline.step(
            w.gravity,
            &w.integration_parameters,
            &mut w.islands,
            &mut w.broad_phase,
            &mut w.narrow_phase,
            &mut w.bodies,
            &mut w.colliders,
            &mut shared.impulse_joints,
            &mut shared.multibody_joints,
            &mut shared.soft_bodies,
            &mut shared.ccd_solver,
            &(),
            &(),
        )
    });
}

impl RapierState {
    /// The walls of an arena of `size`, its obstacles, then one robot disc at each pose, inserted in
    /// the order a [`RapierHost`](super::RapierHost) has them, so that an arena steps alike in both.
    pub(super) fn new(
        size: Vec2,
        mass: f32,
        radius: f32,
        poses: &[Pose],
        obstacles: &Obstacles,
    ) -> Self {
        let mut world = empty_world();
        add_walls(&mut world, size, InteractionGroups::all());
        super::obstacle_contacts::add_colliders(
            &mut world,
            obstacles,
            FRICTION,
            InteractionGroups::all(),
        );
        let bodies: Vec<_> = poses
            .iter()
            .map(|pose| add_robot(&mut world, pose, radius, mass, InteractionGroups::all()))
            .collect();
        let rotations = bodies
            .iter()
            .map(|&b| *world.bodies[b].rotation())
            .collect();
        let translations = bodies
            .iter()
            .map(|&b| world.bodies[b].translation())
            .collect();
        let substeps = world.integration_parameters.num_solver_iterations.max(1);
        let max_lin = world.integration_parameters.max_linear_velocity();
        RapierState {
            world: Box::new(world),
            bodies,
            rotations,
            translations,
            stale: false,
            free_steps: true,
            has_obstacles: !obstacles.is_empty(),
            substeps,
            max_lin,
            hosted: None,
        }
    }

    /// One step of `dt`: without rapier when no contact is possible (see [`Self::free_of_contacts`]),
    /// else a full rapier step. Bodies leaving `lo..hi` are put back (the last guard).
    pub(super) fn step(
        &mut self,
        poses: &mut [Pose],
        velocity: impl Fn(usize) -> (f32, f32),
        step: Step,
        obstacles: &Obstacles,
    ) {
        if let Some(hosted) = &mut self.hosted {
            // Stepped alone: the host's copy falls behind.
            hosted.stale = true;
        }
        if self.free_steps && self.free_of_contacts(step, obstacles) {
            self.free_step(velocity, step.dt);
        } else {
            self.rapier_step(velocity, step.dt);
        }
        let world = &mut self.world;
        settle(
            &mut self.translations,
            &self.rotations,
            poses,
            step,
            |i, q| put_back(&mut world.bodies[self.bodies[i]], q),
        );
    }

    /// True when rapier would find no contact at the start of this step: every robot is farther
    /// than its prediction distance (plus a margin) from the walls, the obstacles and every other
    /// robot. rapier builds its contacts from the poses at the start of a step only, so such a step
    /// has no constraint and moves every body freely.
    pub(super) fn free_of_contacts(&self, step: Step, obstacles: &Obstacles) -> bool {
        let Step { lo, hi, radius, .. } = step;
        let n = self.translations.len();
        if n > FREE_MAX_ROBOTS {
            return false;
        }
        let reach = PREDICTION_DISTANCE + FREE_MARGIN;
        let (inner_lo, inner_hi) = (lo + reach, hi - reach);
        let pair = 2.0 * radius + reach;
        for (i, &p) in self.translations.iter().enumerate() {
            if !(p.cmpgt(inner_lo).all() && p.cmplt(inner_hi).all()) {
                return false;
            }
            if self.translations[i + 1..]
                .iter()
                .any(|&q| p.distance_squared(q) <= pair * pair)
            {
                return false;
            }
        }
        !self.has_obstacles
            || self
                .translations
                .iter()
                .all(|&p| obstacles.overlapping(p, radius + reach, 0.0).is_none())
    }

    /// A step with no contact, integrated exactly as rapier's solver integrates a free body: the
    /// same speed caps and, per substep, the same linearised rotation and translation update, in
    /// the same f32 operations (a test compares the two bit for bit).
    pub(super) fn free_step(&mut self, velocity: impl Fn(usize) -> (f32, f32), dt: f32) {
        let (substeps, max_lin) = (self.substeps, self.max_lin);
        let sub_dt = dt / substeps as f32;
        let max_ang = MAX_ROTATION * (1.0 / dt);
        for (i, (rot, t)) in self
            .rotations
            .iter_mut()
            .zip(&mut self.translations)
            .enumerate()
        {
            let (forward, yaw) = velocity(i);
            let mut lin = heading_vector(*rot) * forward;
            let mut ang = yaw;
            for _ in 0..substeps {
                let n = lin.length();
                if n > max_lin {
                    lin *= max_lin / n;
                }
                if ang.abs() > max_ang {
                    ang = ang.signum() * max_ang;
                }
                let dang = ang * sub_dt;
                let (re, im) = (rot.re, rot.im);
                *rot = Rotation::from_cos_sin_unchecked(re - dang * im, im + dang * re);
                rot.normalize_mut();
                *t += lin * sub_dt;
            }
        }
        self.stale = true;
    }

    /// A full rapier step (after writing the poses free steps moved into rapier's bodies).
    fn rapier_step(&mut self, velocity: impl Fn(usize) -> (f32, f32), dt: f32) {
        self.world.integration_parameters.dt = dt;
        let (translations, rotations) = (&mut self.translations, &mut self.rotations);
        drive_bodies(
            &mut self.world.bodies,
            &self.bodies,
            translations,
            rotations,
            velocity,
            self.stale,
        );
        self.stale = false;
        step_pipeline(&mut self.world);
        read_bodies(&self.world.bodies, &self.bodies, translations, rotations);
    }

    /// Teleports body `i` to `p`, `heading` at rest.
    pub(super) fn set_pose(&mut self, i: usize, p: Vec2, heading: f32) {
        if let Some(hosted) = &mut self.hosted {
            hosted.stale = true;
        }
        if self.stale {
            // Write the other bodies' free moves first: this one's alone would be kept.
            for (k, &handle) in self.bodies.iter().enumerate() {
                let pose = Pose2::from_parts(self.translations[k], self.rotations[k]);
                self.world.bodies[handle].set_position(pose, true);
            }
            self.stale = false;
        }
        let body = &mut self.world.bodies[self.bodies[i]];
        body.set_translation(p, true);
        body.set_rotation(Rotation::new(heading), true);
        self.rotations[i] = *body.rotation();
        self.translations[i] = body.translation();
        body.set_linvel(Vec2::ZERO, true);
        body.set_angvel(0.0, true);
    }
}

/// Writes every robot's body velocity (forward, yaw rate) into its body, and with `write_poses` its
/// mirrored pose too, and wakes the body.
pub(super) fn drive_bodies(
    bodies: &mut RigidBodySet,
    handles: &[RigidBodyHandle],
    translations: &[Vec2],
    rotations: &[Rotation],
    velocity: impl Fn(usize) -> (f32, f32),
    write_poses: bool,
) {
    for (i, &handle) in handles.iter().enumerate() {
        let (forward, yaw) = velocity(i);
        let body = &mut bodies[handle];
        if write_poses {
            body.set_position(Pose2::from_parts(translations[i], rotations[i]), true);
        }
        body.set_linvel(heading_vector(rotations[i]) * forward, true);
        body.set_angvel(yaw, true);
        body.wake_up(true);
    }
}

/// Every body's pose, read back into the mirror.
pub(super) fn read_bodies(
    bodies: &RigidBodySet,
    handles: &[RigidBodyHandle],
    translations: &mut [Vec2],
    rotations: &mut [Rotation],
) {
    for (i, &handle) in handles.iter().enumerate() {
        let body = &bodies[handle];
        rotations[i] = *body.rotation();
        translations[i] = body.translation();
    }
}

/// Puts a body the last guard caught back at `q`, stopped.
pub(super) fn put_back(body: &mut RigidBody, q: Vec2) {
    body.set_translation(q, false);
    body.set_linvel(Vec2::ZERO, false);
}

/// The last guard after a step: every mirrored position outside `lo..hi` of `step` (or not finite)
/// is put back inside (`fix` is told, to put its body back and stop it), and `poses` take the
/// mirror's values.
pub(super) fn settle(
    translations: &mut [Vec2],
    rotations: &[Rotation],
    poses: &mut [Pose],
    step: Step,
    mut fix: impl FnMut(usize, Vec2),
) {
    let Step { lo, hi, .. } = step;
    for (i, pose) in poses.iter_mut().enumerate() {
        let p = translations[i];
        let heading = rotations[i].angle();
        let q = p.clamp(lo, hi);
        if q != p || !q.is_finite() {
            let q = if q.is_finite() { q } else { pose.pos };
            fix(i, q);
            translations[i] = q;
            *pose = Pose { pos: q, heading };
        } else {
            *pose = Pose { pos: p, heading };
        }
    }
}

/// The unit vector along a body's heading: its rotation's own cosine and sine (rapier keeps the
/// rotation normalised), without the round trip through an angle.
pub(super) fn heading_vector(rotation: Rotation) -> Vec2 {
    Vec2::new(rotation.re, rotation.im)
}
