//! Static obstacles in the arena (`[[obstacles]]`): parry2d shapes with a uniform-grid broad phase.
//!
//! Every obstacle becomes one or more *parts* (a parry2d shape at a pose: a box, a ball, a convex
//! piece of a polygon, a capsule per wall segment, a box per run of mask pixels). The parts are
//! bucketed into a grid over the arena, so the queries of the bumpers (three short rays per robot),
//! of the disc solver (push a robot out) and of placement (is this spot free?) look at the parts near
//! the robot only, never at all of them.
mod boundary;
mod mask;
mod printed;
mod shapes;
mod spec;

pub use boundary::{BOUNDARY, BOUNDARY_THICKNESS, Inside};
pub use mask::{MaskRect, merge_runs, solid_rects};
pub use printed::Printed;
pub use spec::{ArenaShape, ObstacleKind, ObstacleShape, ObstacleSpec};

use crate::error::Result;
use glam::Vec2;
use parry2d::math::Pose;
use parry2d::query::Ray;
use parry2d::shape::SharedShape;
use std::path::Path;
use std::sync::Arc;

/// Most grid cells per axis: bounds the table for tiny obstacles in a large arena.
const MAX_CELLS_PER_AXIS: f32 = 256.0;
/// Push-out passes of [`Obstacles::push_out`] (a disc wedged between two parts needs more than one).
const PUSH_PASSES: usize = 4;

/// One parry2d shape of an obstacle, with its bounds and first grid cell.
#[derive(Clone)]
pub struct Part {
    pub shape: SharedShape,
    pub pose: Pose,
    /// Axis-aligned bounds, m.
    pub lo: Vec2,
    pub hi: Vec2,
    /// Index of the `[[obstacles]]` entry it belongs to.
    pub obstacle: u32,
    /// The lowest grid cell (x, y) it covers: a query visits a part in one cell only.
    cell0: [u32; 2],
}

/// The obstacles of one arena, ready for queries. Empty (and free to query) when the scenario has none.
#[derive(Clone, Default)]
pub struct Obstacles {
    parts: Vec<Part>,
    /// Closed outlines (obstacle index, vertices in m), for drawing.
    outlines: Vec<(usize, Vec<Vec2>)>,
    cell: f32,
    dims: [u32; 2],
    /// `starts[k]..starts[k + 1]` indexes `items` for cell `k`.
    starts: Vec<u32>,
    items: Vec<u32>,
    /// Where robots may be, for an arena of another shape than its rectangle.
    inside: Option<Inside>,
    /// The obstacles drawn on the screen (`kind = "printed"`), apart from the physical ones.
    printed: Option<Arc<Printed>>,
}

impl Obstacles {
    /// The obstacles of `specs` in an arena of `arena` size (m), image masks read relative to
    /// `base_dir`. Errors name the key (`obstacles[2].size`) and why.
    pub fn build(specs: &[ObstacleSpec], arena: Vec2, base_dir: &Path) -> Result<Obstacles> {
        Self::build_in(specs, None, arena, base_dir)
    }

    /// [`Self::build`] in an arena bounded by `shape` (a disc or polygon wall within the rectangle).
    pub fn build_in(
        specs: &[ObstacleSpec],
        shape: Option<&ArenaShape>,
        arena: Vec2,
        base_dir: &Path,
    ) -> Result<Obstacles> {
        let mut out = Obstacles::default();
        if let Some(shape) = shape {
            boundary::add(&mut out, shape, arena)?;
        }
        let mut printed = Printed::default();
        for (i, spec) in specs.iter().enumerate() {
            if spec.kind == ObstacleKind::Printed {
                shapes::add(&mut printed.layer, i, spec, arena, base_dir)?;
            } else {
                shapes::add(&mut out, i, spec, arena, base_dir)?;
            }
        }
        out.index(arena);
        if !printed.layer.parts.is_empty() {
            printed.layer.index(arena);
            printed.colours = specs.iter().map(|s| s.colour.unwrap_or([0; 3])).collect();
            out.printed = Some(Arc::new(printed));
        }
        Ok(out)
    }

    /// True when there are no physical obstacles (nothing to collide with or see by bumper).
    pub fn is_empty(&self) -> bool {
        self.parts.is_empty()
    }

    /// The printed obstacles, if any.
    pub fn printed(&self) -> Option<&Printed> {
        self.printed.as_deref()
    }

    /// Whether a disc of `radius` at `p` lies within the arena's shape (always, for a rectangle).
    pub fn holds(&self, p: Vec2, radius: f32) -> bool {
        self.inside.as_ref().is_none_or(|i| i.holds(p, radius))
    }

    /// The parry2d parts (for rapier colliders).
    pub fn parts(&self) -> &[Part] {
        &self.parts
    }

    /// Closed outlines `(obstacle index, vertices)` in m, for drawing.
    pub fn outlines(&self) -> &[(usize, Vec<Vec2>)] {
        &self.outlines
    }

    fn push(&mut self, obstacle: usize, shape: SharedShape, pose: Pose) {
        let aabb = shape.compute_aabb(&pose);
        self.parts.push(Part {
            shape,
            pose,
            lo: aabb.mins,
            hi: aabb.maxs,
            obstacle: obstacle as u32,
            cell0: [0, 0],
        });
    }

    /// Buckets the parts into the grid (a counting sort into flat arrays).
    fn index(&mut self, arena: Vec2) {
        if self.parts.is_empty() {
            return;
        }
        // Cells about the size of the typical part, at least 2 cm (a robot's diameter is 4 cm).
        let mean = self
            .parts
            .iter()
            .map(|p| (p.hi - p.lo).max_element())
            .sum::<f32>()
            / self.parts.len() as f32;
        let side = arena.max_element().max(1e-3);
        let cell = mean.max(0.02).max(side / MAX_CELLS_PER_AXIS);
        self.cell = cell;
        let nx = ((arena.x / cell).ceil() as u32).max(1);
        let ny = ((arena.y / cell).ceil() as u32).max(1);
        self.dims = [nx, ny];
        let ncells = (nx * ny) as usize;
        let mut counts = vec![0u32; ncells + 1];
        for k in 0..self.parts.len() {
            let (x0, x1, y0, y1) = self.cell_range(self.parts[k].lo, self.parts[k].hi);
            self.parts[k].cell0 = [x0, y0];
            for y in y0..y1 {
                for x in x0..x1 {
                    counts[(y * nx + x) as usize + 1] += 1;
                }
            }
        }
        for k in 0..ncells {
            counts[k + 1] += counts[k];
        }
        let mut fill = counts.clone();
        self.items = vec![0; counts[ncells] as usize];
        for (k, part) in self.parts.iter().enumerate() {
            let (x0, x1, y0, y1) = self.cell_range(part.lo, part.hi);
            for y in y0..y1 {
                for x in x0..x1 {
                    let c = (y * nx + x) as usize;
                    self.items[fill[c] as usize] = k as u32;
                    fill[c] += 1;
                }
            }
        }
        self.starts = counts;
    }

    /// Half-open cell ranges (x0..x1, y0..y1) covering the box `lo..hi`, clamped to the grid.
    #[inline]
    fn cell_range(&self, lo: Vec2, hi: Vec2) -> (u32, u32, u32, u32) {
        let [nx, ny] = self.dims;
        let inv = 1.0 / self.cell;
        // `as u32` saturates negatives (and NaN) to 0.
        let c = |v: f32, n: u32| ((v * inv) as u32).min(n - 1);
        (c(lo.x, nx), c(hi.x, nx) + 1, c(lo.y, ny), c(hi.y, ny) + 1)
    }

    /// Calls `f` once for every part whose bounds meet the box `lo..hi`.
    #[inline]
    pub fn for_each_near(&self, lo: Vec2, hi: Vec2, mut f: impl FnMut(&Part)) {
        if self.parts.is_empty() || !(lo.is_finite() && hi.is_finite()) {
            return;
        }
        let (x0, x1, y0, y1) = self.cell_range(lo, hi);
        let nx = self.dims[0];
        for y in y0..y1 {
            for x in x0..x1 {
                let c = (y * nx + x) as usize;
                for &k in &self.items[self.starts[c] as usize..self.starts[c + 1] as usize] {
                    let part = &self.parts[k as usize];
                    // A part spanning several cells of the query is visited in the first of them.
                    if x != x0.max(part.cell0[0]) || y != y0.max(part.cell0[1]) {
                        continue;
                    }
                    if part.hi.x < lo.x || part.lo.x > hi.x || part.hi.y < lo.y || part.lo.y > hi.y
                    {
                        continue;
                    }
                    f(part);
                }
            }
        }
    }

    /// Distance along the unit ray `o + t d` to the first obstacle, at most `max`; 0 when `o` is
    /// inside one; `max` when none is nearer.
    pub fn ray(&self, o: Vec2, d: Vec2, max: f32) -> f32 {
        let end = o + d * max;
        let mut best = max;
        let ray = Ray::new(o, d);
        self.for_each_near(o.min(end), o.max(end), |part| {
            if let Some(t) = part.shape.cast_ray(&part.pose, &ray, best, true) {
                best = best.min(t);
            }
        });
        best
    }

    /// [`Self::ray`] for several rays starting within `reach` of `centre` and no longer than
    /// `reach` from it: one grid query for all of them (a robot's three bumper rays). `dists` holds
    /// each ray's length on entry and its distance to the first obstacle within it on return.
    pub fn rays<const N: usize>(
        &self,
        centre: Vec2,
        reach: f32,
        origins: &[Vec2; N],
        dirs: &[Vec2; N],
        dists: &mut [f32; N],
    ) {
        let r = Vec2::splat(reach);
        self.for_each_near(centre - r, centre + r, |part| {
            for s in 0..N {
                // Most rays near a part miss its bounds: a slab test spares the shape's ray cast.
                if !ray_meets_box(origins[s], dirs[s], dists[s], part.lo, part.hi) {
                    continue;
                }
                let ray = Ray::new(origins[s], dirs[s]);
                if let Some(t) = part.shape.cast_ray(&part.pose, &ray, dists[s], true) {
                    dists[s] = dists[s].min(t);
                }
            }
        });
    }

    /// The obstacle (index in `[[obstacles]]`) that a disc of `radius` at `p` overlaps by more than
    /// `slack` m, if any.
    pub fn overlapping(&self, p: Vec2, radius: f32, slack: f32) -> Option<usize> {
        let mut hit = None;
        let r = Vec2::splat(radius);
        self.for_each_near(p - r, p + r, |part| {
            if hit.is_some() {
                return;
            }
            let proj = part.shape.project_point(&part.pose, p, false);
            let dist = proj.point.distance(p);
            if proj.is_inside || dist < radius - slack {
                hit = Some(part.obstacle as usize);
            }
        });
        hit
    }

    /// `p` moved the least so that a disc of `radius` there overlaps no obstacle (a few passes of
    /// projections onto the nearest surface; a disc wedged in a gap narrower than its diameter ends
    /// at the best compromise).
    pub fn push_out(&self, mut p: Vec2, radius: f32) -> Vec2 {
        if self.parts.is_empty() || !p.is_finite() {
            return p;
        }
        for _ in 0..PUSH_PASSES {
            let mut moved = false;
            let r = Vec2::splat(radius);
            self.for_each_near(p - r, p + r, |part| {
                let proj = part.shape.project_point(&part.pose, p, false);
                let away = p - proj.point;
                let dist = away.length();
                let target = if proj.is_inside {
                    // Centre inside: out through the nearest face (the other way from `p`).
                    let out = if dist > 1e-9 {
                        -away / dist
                    } else {
                        (p - part.pose.translation).normalize_or(Vec2::X)
                    };
                    proj.point + out * radius
                } else if dist < radius {
                    let out = if dist > 1e-9 {
                        away / dist
                    } else {
                        (p - part.pose.translation).normalize_or(Vec2::X)
                    };
                    proj.point + out * radius
                } else {
                    return;
                };
                if target != p {
                    p = target;
                    moved = true;
                }
            });
            if !moved {
                break;
            }
        }
        p
    }
}

/// Whether the segment `o + t d`, `t` in `[0, len]`, meets the box `lo..hi` (slab test).
#[inline]
fn ray_meets_box(o: Vec2, d: Vec2, len: f32, lo: Vec2, hi: Vec2) -> bool {
    let inv = d.recip();
    let (t1, t2) = ((lo - o) * inv, (hi - o) * inv);
    let (near, far) = (t1.min(t2), t1.max(t2));
    // A ray running exactly along a box edge (0 * inf = NaN, ignored by min/max) counts as a miss.
    let enter = near.x.max(near.y).max(0.0);
    let exit = far.x.min(far.y).min(len);
    // Neither is NaN: `f32::max` and `min` return the other operand.
    enter <= exit
}
