//! Three IR bumpers (front-left, front, front-right).
use crate::arena::Obstacles;
use crate::robot::Pose;
use crate::spatial::NeighbourIndex;
use glam::Vec2;
use serde::{Deserialize, Serialize};

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct BumperParams {
    /// Range of the IR sensors from the robot's rim, m.
    pub range: f32,
    /// Directions of the three sensors relative to the heading, rad (front-left, front, front-right).
    pub angles: [f32; 3],
}

impl Default for BumperParams {
    fn default() -> Self {
        BumperParams {
            range: 0.02,
            angles: [
                std::f32::consts::FRAC_PI_4,
                0.0,
                -std::f32::consts::FRAC_PI_4,
            ],
        }
    }
}

/// The three bumper rays in the robot frame (unit vectors at [`BumperParams::angles`]), computed once
/// per world: each reading then takes one `sin_cos` of the heading instead of three.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BumperRays {
    range: f32,
    local: [Vec2; 3],
}

impl BumperRays {
    pub fn new(params: &BumperParams) -> Self {
        BumperRays {
            range: params.range,
            local: params.angles.map(Vec2::from_angle),
        }
    }
}

/// Reading of an IR bumper whose first obstacle is `distance` m from the robot's rim: `1 - d / range`
/// inside the range, 0 beyond it (and for a non-positive range).
pub fn reading_for_distance(distance: f32, range: f32) -> f32 {
    let inside = range > 0.0 && distance < range;
    if !inside {
        return 0.0;
    }
    (1.0 - distance.max(0.0) / range).clamp(0.0, 1.0)
}

/// Distance along the unit ray `o + t d` (t >= 0) to the first point inside the disc `(c, radius)`;
/// 0 when `o` is already inside, `None` when the ray misses.
pub fn ray_disc(o: Vec2, d: Vec2, c: Vec2, radius: f32) -> Option<f32> {
    let m = o - c;
    let cc = m.length_squared() - radius * radius;
    if cc <= 0.0 {
        return Some(0.0);
    }
    let b = m.dot(d);
    if b >= 0.0 {
        return None;
    }
    let disc = b * b - cc;
    if disc < 0.0 {
        return None;
    }
    Some((-b - disc.sqrt()).max(0.0))
}

/// Distance along the unit ray `o + t d` to the boundary of the arena `[0, w] x [0, h]`; 0 when `o`
/// is on or outside it.
pub fn ray_walls(o: Vec2, d: Vec2, arena: Vec2) -> f32 {
    if !(o.x > 0.0 && o.y > 0.0 && o.x < arena.x && o.y < arena.y) {
        return 0.0;
    }
    let mut t = f32::INFINITY;
    if d.x > 0.0 {
        t = t.min((arena.x - o.x) / d.x);
    } else if d.x < 0.0 {
        t = t.min(-o.x / d.x);
    }
    if d.y > 0.0 {
        t = t.min((arena.y - o.y) / d.y);
    } else if d.y < 0.0 {
        t = t.min(-o.y / d.y);
    }
    t
}

impl NeighbourIndex {
    /// The smallest cell that keeps bumper queries to 3 x 3 cells.
    pub fn cell_for(radius: f32, params: &BumperParams) -> f32 {
        2.0 * radius + params.range.max(0.0)
    }

    /// Readings in [0, 1] of robot `index`'s bumpers against walls of an arena of `arena` size and the
    /// other robots (all of radius `radius`).
    ///
    /// Each sensor is a ray from the rim (`centre + radius * dir`) along its direction; the reading is
    /// `1 - d / range` for the first wall or robot disc at distance `d < range`, 0 if none; a sensor
    /// whose rim point is already inside another robot (or beyond a wall) reads 1. Uses the index as
    /// last rebuilt: rebuild it with the current positions first.
    pub fn bumpers(
        &self,
        index: usize,
        poses: &[Pose],
        radius: f32,
        arena: Vec2,
        rays: &BumperRays,
    ) -> [f32; 3] {
        let Some(me) = poses.get(index) else {
            return [0.0; 3];
        };
        let none = Obstacles::default();
        self.bumpers_facing(index, poses, me.forward(), radius, arena, rays, &none)
    }

    /// [`Self::bumpers`] with robot `index`'s heading vector (`poses[index].forward()`, which the
    /// caller computes once for its colour sensors too) in an arena with `obstacles`: each ray also
    /// stops at the first obstacle (parry2d ray casts against the parts near the robot, found in the
    /// obstacles' grid).
    #[allow(clippy::too_many_arguments)]
    pub fn bumpers_facing(
        &self,
        index: usize,
        poses: &[Pose],
        forward: Vec2,
        radius: f32,
        arena: Vec2,
        rays: &BumperRays,
        obstacles: &Obstacles,
    ) -> [f32; 3] {
        let Some(me) = poses.get(index) else {
            return [0.0; 3];
        };
        let range = rays.range;
        let mut readings = [0.0f32; 3];
        if range.is_nan() || range <= 0.0 {
            return readings;
        }
        let mut dists = [range; 3];
        let mut dirs = [Vec2::ZERO; 3];
        let mut origins = [Vec2::ZERO; 3];
        // A robot farther from every wall than its rays reach (with a 1 % margin, and 1e-5 of the
        // arena's size for the rounding of coordinates) has no wall within range: `ray_walls` of a
        // ray of at most unit length from inside would exceed `range`, which the minimum leaves as it
        // is. Most robots, most steps.
        let margin = (radius.abs() + range) * 1.01 + arena.x.abs().max(arena.y.abs()) * 1e-5;
        let p = me.pos;
        let far_from_walls =
            p.x > margin && p.y > margin && p.x < arena.x - margin && p.y < arena.y - margin;
        for s in 0..3 {
            let d = forward.rotate(rays.local[s]);
            dirs[s] = d;
            origins[s] = me.pos + radius * d;
            // (A NaN or overlong direction takes `ray_walls`, which reads it as a contact.)
            if !(far_from_walls && d.length_squared() <= 1.0001) {
                dists[s] = dists[s].min(ray_walls(origins[s], d, arena));
            }
        }
        if !obstacles.is_empty() {
            obstacles.rays(me.pos, radius + range, &origins, &dirs, &mut dists);
        }
        let reach = 2.0 * radius + range;
        let reach2 = reach * reach;
        self.for_each_near(me.pos, reach, |j| {
            if j == index {
                return;
            }
            let Some(other) = poses.get(j) else { return };
            if (other.pos - me.pos).length_squared() > reach2 {
                return;
            }
            for s in 0..3 {
                if let Some(t) = ray_disc(origins[s], dirs[s], other.pos, radius) {
                    dists[s] = dists[s].min(t);
                }
            }
        });
        for s in 0..3 {
            readings[s] = reading_for_distance(dists[s], range);
        }
        readings
    }
}
