//! Robots against the arena's static obstacles, for both solvers: fixed rapier colliders built from
//! the obstacles' parry2d parts, and the disc solver's push-out (each disc moved off the nearest
//! surfaces by parry2d point projections, found through the obstacles' grid).
use super::Pose;
use crate::arena::Obstacles;
use glam::Vec2;
use rapier2d::prelude::{ColliderBuilder, InteractionGroups, PhysicsWorld};

/// Adds every obstacle part to `world` as a fixed collider (no body: it never moves), in collision
/// `groups`.
pub(super) fn add_colliders(
    world: &mut PhysicsWorld,
    obstacles: &Obstacles,
    friction: f32,
    groups: InteractionGroups,
) {
    for part in obstacles.parts() {
        world.insert_collider(
            ColliderBuilder::new(part.shape.clone())
                .position(part.pose)
                .friction(friction)
                .restitution(0.0)
                .collision_groups(groups),
            None,
        );
    }
}

/// Moves every robot disc (`radius`) off the obstacles, keeping centres within `lo..hi` (the walls).
pub(super) fn push_out(poses: &mut [Pose], radius: f32, obstacles: &Obstacles, lo: Vec2, hi: Vec2) {
    if obstacles.is_empty() {
        return;
    }
    for pose in poses {
        let p = obstacles.push_out(pose.pos, radius);
        if p.is_finite() {
            pose.pos = p.clamp(lo, hi);
        }
    }
}
