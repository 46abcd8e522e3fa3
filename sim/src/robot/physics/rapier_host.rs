//! Many small arenas in one rapier world, stepped by one pipeline call.
//!
//! rapier's step has a fixed cost (its stages, and the cache misses of pulling a whole world in) that
//! dwarfs the work of an arena of a few robots. A batch of such arenas (an RL environment's worlds)
//! shares one [`RapierHost`]: every arena keeps its own coordinates and its robots their own
//! collision group, so arenas pass through each other unseen and share one set of walls and
//! obstacles. An arena whose next step has no possible contact takes its exact free step (see
//! `RapierState::free_step`) with its bodies asleep in the host, which then costs rapier nothing; the
//! others are stepped together.
//!
//! A step in a host is split in two: each arena's [`ArenaPhysics::step_in`] (a free step, or its
//! velocities written into the host), then [`RapierHost::step`] once, then each arena's
//! [`ArenaPhysics::finish_in`] (its poses read back). Results are deterministic for a fixed
//! assignment of arenas to hosts and slots, and the same as the arena's alone while no robot touches
//! two things at once; where one does, the order in which rapier solves those contacts depends on
//! the other arenas' pairs, and the poses may differ in their last bits.
//!
//! [`ArenaPhysics::step_in`]: super::ArenaPhysics::step_in
//! [`ArenaPhysics::finish_in`]: super::ArenaPhysics::finish_in
use super::Step;
use super::rapier::{self, HostedArena, RapierState, settle};
use crate::arena::Obstacles;
use crate::robot::Pose;
use glam::Vec2;
use rapier2d::prelude::{
    Group, InteractionGroups, InteractionTestMode, PhysicsWorld, RigidBodyHandle,
};

/// Most arenas one host holds: each takes one collision group bit, and the walls and obstacles the
/// last of rapier's 32.
pub const MAX_HOSTED_ARENAS: usize = 31;

/// One rapier world stepping many arenas of the same size and obstacles.
pub struct RapierHost {
    world: Box<PhysicsWorld>,
    size: Vec2,
    /// The bounds of every obstacle part, to recognise arenas with the same obstacles.
    obstacle_bounds: Vec<(Vec2, Vec2)>,
    slots: Vec<HostSlot>,
    /// Arenas whose bodies wait for the next pipeline step.
    pending: usize,
}

/// The bodies of one arena slot, and whether they are awake in rapier.
#[derive(Default)]
struct HostSlot {
    bodies: Vec<RigidBodyHandle>,
    awake: bool,
}

fn bounds(obstacles: &Obstacles) -> Vec<(Vec2, Vec2)> {
    obstacles.parts().iter().map(|p| (p.lo, p.hi)).collect()
}

fn static_groups() -> InteractionGroups {
    InteractionGroups::new(Group::GROUP_32, Group::ALL, InteractionTestMode::And)
}

fn arena_groups(slot: usize) -> InteractionGroups {
    let own = Group::from_bits_truncate(1 << slot);
    InteractionGroups::new(own, own | Group::GROUP_32, InteractionTestMode::And)
}

impl RapierHost {
    /// A host for up to `arenas` arenas (at most [`MAX_HOSTED_ARENAS`]) of `size` (m) with these
    /// static obstacles.
    pub fn new(size: Vec2, obstacles: &Obstacles, arenas: usize) -> Self {
        let mut world = rapier::empty_world();
        let size = size.max(Vec2::ZERO);
        rapier::add_walls(&mut world, size, static_groups());
        super::obstacle_contacts::add_colliders(
            &mut world,
            obstacles,
            super::FRICTION,
            static_groups(),
        );
        let slots = (0..arenas.min(MAX_HOSTED_ARENAS))
            .map(|_| HostSlot::default())
            .collect();
        RapierHost {
            world: Box::new(world),
            size,
            obstacle_bounds: bounds(obstacles),
            slots,
            pending: 0,
        }
    }

    /// Whether an arena of `size` with these obstacles may live in this host: the host's walls and
    /// obstacles are the ones its arenas meet.
    pub fn fits(&self, size: Vec2, obstacles: &Obstacles) -> bool {
        size == self.size && bounds(obstacles) == self.obstacle_bounds
    }

    /// Bodies rapier simulates now: those of arenas whose last step had a possible contact (the
    /// others sleep).
    pub fn active_bodies(&self) -> usize {
        self.world.islands.num_active_bodies()
    }

    /// One rapier step of `dt` for every arena that asked for one since the last call.
    pub fn step(&mut self, dt: f32) {
        if self.pending == 0 {
            return;
        }
        self.world.integration_parameters.dt = dt;
        rapier::step_pipeline(&mut self.world);
        self.pending = 0;
    }
}

impl RapierState {
    /// Moves this arena's full steps into `host`'s `slot`: fresh bodies at the mirrored poses
    /// (whatever the slot held before is removed). Returns false when the slot does not exist.
    pub(super) fn attach(
        &mut self,
        host: &mut RapierHost,
        slot: usize,
        radius: f32,
        mass: f32,
    ) -> bool {
        let Some(entry) = host.slots.get_mut(slot) else {
            return false;
        };
        for handle in entry.bodies.drain(..) {
            host.world.remove_body(handle);
        }
        let groups = arena_groups(slot);
        for (t, r) in self.translations.iter().zip(&self.rotations) {
            let pose = Pose {
                pos: *t,
                heading: r.angle(),
            };
            let body = rapier::add_robot(&mut host.world, &pose, radius, mass, groups);
            // The mirror's own rotation, not one rebuilt from its angle.
            host.world.bodies[body].set_rotation(*r, false);
            entry.bodies.push(body);
        }
        entry.awake = true;
        self.hosted = Some(HostedArena {
            slot,
            stale: false,
            pending: false,
        });
        true
    }

    /// The first half of a step in the host: a free step when no contact is possible (the arena's
    /// bodies sleep in the host), else the velocities written into the host's bodies for its next
    /// step. Without a host (not attached) this is a whole step alone.
    pub(super) fn step_in(
        &mut self,
        host: &mut RapierHost,
        poses: &mut [Pose],
        velocity: impl Fn(usize) -> (f32, f32),
        step: Step,
        obstacles: &Obstacles,
    ) {
        let Some(hosted) = self.hosted.as_ref() else {
            return self.step(poses, velocity, step, obstacles);
        };
        let slot = &mut host.slots[hosted.slot];
        if self.free_steps && self.free_of_contacts(step, obstacles) {
            if slot.awake {
                for &handle in &slot.bodies {
                    host.world.bodies[handle].sleep();
                }
                slot.awake = false;
            }
            self.free_step(velocity, step.dt);
            if let Some(hosted) = &mut self.hosted {
                hosted.stale = true;
            }
            settle(
                &mut self.translations,
                &self.rotations,
                poses,
                step,
                |_, _| {},
            );
            return;
        }
        rapier::drive_bodies(
            &mut host.world.bodies,
            &slot.bodies,
            &self.translations,
            &self.rotations,
            velocity,
            hosted.stale,
        );
        slot.awake = true;
        host.pending += 1;
        // The arena's own world no longer holds its poses.
        self.stale = true;
        if let Some(hosted) = &mut self.hosted {
            hosted.stale = false;
            hosted.pending = true;
        }
    }

    /// The second half of a step in the host, after [`RapierHost::step`]: the poses of an arena
    /// that went through rapier are read back (and guarded).
    pub(super) fn finish_in(&mut self, host: &mut RapierHost, poses: &mut [Pose], step: Step) {
        let Some(hosted) = self.hosted.as_mut().filter(|h| h.pending) else {
            return;
        };
        hosted.pending = false;
        let bodies = &mut host.world.bodies;
        let handles = &host.slots[hosted.slot].bodies;
        rapier::read_bodies(bodies, handles, &mut self.translations, &mut self.rotations);
        settle(
            &mut self.translations,
            &self.rotations,
            poses,
            step,
            |i, q| rapier::put_back(&mut bodies[handles[i]], q),
        );
    }
}
