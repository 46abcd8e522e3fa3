//! Three IR bumpers (front-left, front, front-right) and a spatial index of robots for them.
use crate::robot::Pose;
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

/// Up to this many robots the index is a single cell: every robot is a candidate neighbour.
const SCAN_ALL_BELOW: usize = 32;

/// Uniform-grid hash of robot positions, rebuilt each step, so bumpers need no ray casts.
///
/// Cell lists are built by a counting sort into flat arrays that are reused between rebuilds (no
/// allocation once the robot count and grid size settle). Use a cell of at least `2 * radius + range`
/// so that a robot's bumpers only need the 3 x 3 cells around it (smaller cells still work, they just
/// look at more cells).
#[derive(Default)]
pub struct NeighbourIndex {
    cell: f32,
    dims: [usize; 2],
    /// `starts[k]..starts[k + 1]` indexes `items` for cell `k`.
    starts: Vec<u32>,
    /// Robot indices sorted by cell.
    items: Vec<u32>,
    /// Cell of each robot.
    cell_of: Vec<u32>,
}

impl NeighbourIndex {
    /// The smallest cell that keeps bumper queries to 3 x 3 cells.
    pub fn cell_for(radius: f32, params: &BumperParams) -> f32 {
        2.0 * radius + params.range.max(0.0)
    }

    pub fn rebuild(&mut self, arena: Vec2, cell: f32, positions: &[Vec2]) {
        // A handful of robots (a small world of a batched environment) is faster to scan than to
        // bucket: one cell over the whole arena. Bumper readings are a minimum over the candidates, so
        // they do not depend on the cell size.
        let whole_arena = arena.x.max(arena.y).max(1e-3);
        let cell = if positions.len() <= SCAN_ALL_BELOW {
            whole_arena
        } else if cell.is_finite() && cell > 0.0 {
            cell
        } else {
            whole_arena
        };
        // Bound the grid so a tiny cell cannot make a huge table.
        let max_cells_per_axis = 4096.0;
        let cell = cell
            .max(arena.x / max_cells_per_axis)
            .max(arena.y / max_cells_per_axis);
        self.cell = cell;
        if positions.len() <= SCAN_ALL_BELOW {
            // One cell (its bounds still clamp a query): the robots in index order, no sort.
            self.dims = [1, 1];
            self.starts.clear();
            self.starts.extend([0, positions.len() as u32]);
            self.cell_of.clear();
            self.cell_of.resize(positions.len(), 0);
            self.items.clear();
            self.items.extend(0..positions.len() as u32);
            return;
        }
        let nx = ((arena.x / cell).ceil() as usize).max(1);
        let ny = ((arena.y / cell).ceil() as usize).max(1);
        self.dims = [nx, ny];
        let ncells = nx * ny;
        self.starts.clear();
        self.starts.resize(ncells + 1, 0);
        self.cell_of.clear();
        for &p in positions {
            let k = self.cell_index(p);
            self.cell_of.push(k as u32);
            self.starts[k + 1] += 1;
        }
        for k in 0..ncells {
            self.starts[k + 1] += self.starts[k];
        }
        self.items.clear();
        self.items.resize(positions.len(), 0);
        // Fill from the back of each cell so robots stay in index order within a cell.
        for (i, &k) in self.cell_of.iter().enumerate().rev() {
            let k = k as usize + 1;
            self.starts[k] -= 1;
            self.items[self.starts[k] as usize] = i as u32;
        }
        // After the fill, starts[k + 1] is the beginning of cell k: shift back by one.
        self.starts.rotate_left(1);
        self.starts[ncells] = positions.len() as u32;
    }

    /// Robots whose cell lies within `reach` of `p` (a superset of those within `reach`).
    pub fn near(&self, p: Vec2, reach: f32) -> impl Iterator<Item = usize> + '_ {
        let (x0, x1, y0, y1) = self.cell_range(p, reach);
        let nx = self.dims[0];
        (y0..y1).flat_map(move |y| {
            let a = self.starts[y * nx + x0] as usize;
            let b = self.starts[y * nx + x1] as usize;
            self.items[a..b].iter().map(|&i| i as usize)
        })
    }

    /// Calls `f` for every robot whose cell lies within `reach` of `p`, in a fixed order (the same
    /// robots as [`Self::near`], without the iterator overhead).
    #[inline]
    pub fn for_each_near(&self, p: Vec2, reach: f32, mut f: impl FnMut(usize)) {
        let (x0, x1, y0, y1) = self.cell_range(p, reach);
        let nx = self.dims[0];
        for y in y0..y1 {
            let a = self.starts[y * nx + x0] as usize;
            let b = self.starts[y * nx + x1] as usize;
            for &i in &self.items[a..b] {
                f(i as usize);
            }
        }
    }

    /// Half-open cell ranges (x0..x1, y0..y1) covering the square of half-side `reach` around `p`.
    #[inline]
    fn cell_range(&self, p: Vec2, reach: f32) -> (usize, usize, usize, usize) {
        let [nx, ny] = self.dims;
        if nx == 0 || ny == 0 || !(p.is_finite() && reach.is_finite()) {
            return (0, 0, 0, 0);
        }
        let inv = 1.0 / self.cell;
        // `as usize` saturates negatives to 0 (and truncation is floor for non-negatives).
        let c = |v: f32, n: usize| ((v * inv) as usize).min(n - 1);
        (
            c(p.x - reach, nx),
            c(p.x + reach, nx) + 1,
            c(p.y - reach, ny),
            c(p.y + reach, ny) + 1,
        )
    }

    fn cell_index(&self, p: Vec2) -> usize {
        let [nx, ny] = self.dims;
        // `as usize` saturates negatives to 0 and truncates the rest: `floor(v / cell).max(0)`
        // without a libm `floorf` call (baseline x86-64 has no rounding instruction).
        let c = |v: f32, n: usize| {
            if v.is_finite() {
                ((v / self.cell) as usize).min(n - 1)
            } else {
                0
            }
        };
        c(p.y, ny) * nx + c(p.x, nx)
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
        let range = rays.range;
        let mut readings = [0.0f32; 3];
        if range.is_nan() || range <= 0.0 {
            return readings;
        }
        let mut dists = [range; 3];
        let mut dirs = [Vec2::ZERO; 3];
        let mut origins = [Vec2::ZERO; 3];
        let forward = me.forward();
        for s in 0..3 {
            let d = forward.rotate(rays.local[s]);
            dirs[s] = d;
            origins[s] = me.pos + radius * d;
            dists[s] = dists[s].min(ray_walls(origins[s], d, arena));
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
