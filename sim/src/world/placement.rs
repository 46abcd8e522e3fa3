//! Initial robot placement: random without overlap, on a grid, or explicit.
use crate::error::{Result, SimError};
use crate::rng::SimRng;
use crate::robot::Pose;
use crate::scenario::{Placement, RobotGroupSpec};
use glam::Vec2;
use rand::RngExt;

/// Poses for one group, avoiding the robots already placed in `taken`.
pub(super) fn place_group(
    group: &RobotGroupSpec,
    key: &str,
    arena: Vec2,
    radius: f32,
    taken: &[Pose],
    rng: &mut SimRng,
) -> Result<Vec<Pose>> {
    let region = group.region.unwrap_or([0.0, 0.0, arena.x, arena.y]);
    // Keep a small gap from the walls and between robots so that no contact exists at t = 0.
    let gap = 0.002;
    let (lo, hi) = (
        Vec2::new(region[0].max(radius + gap), region[1].max(radius + gap)),
        Vec2::new(
            region[2].min(arena.x - radius - gap),
            region[3].min(arena.y - radius - gap),
        ),
    );
    match group.placement {
        Placement::Explicit => Ok(group
            .poses
            .iter()
            .map(|p| Pose::new(p[0], p[1], p[2].to_radians()))
            .collect()),
        Placement::Grid => {
            let n = group.count;
            let size = hi - lo;
            let cols =
                ((n as f32 * size.x / size.y.max(1e-9)).sqrt().ceil() as usize).clamp(1, n.max(1));
            let rows = n.div_ceil(cols);
            let step = Vec2::new(size.x / cols as f32, size.y / rows.max(1) as f32);
            if step.min_element() < 2.0 * radius {
                return Err(SimError::invalid(
                    format!("{key}.count"),
                    n,
                    "too many robots for a grid in this region",
                ));
            }
            Ok((0..n)
                .map(|k| {
                    let (c, r) = (k % cols, k / cols);
                    let pos = lo + Vec2::new((c as f32 + 0.5) * step.x, (r as f32 + 0.5) * step.y);
                    Pose {
                        pos,
                        heading: rng.random_range(-std::f32::consts::PI..std::f32::consts::PI),
                    }
                })
                .collect())
        }
        Placement::Random => {
            let mut placed: Vec<Pose> = Vec::with_capacity(group.count);
            let min_d2 = (2.0 * radius + gap).powi(2);
            let clear = |p: Vec2, placed: &[Pose]| {
                taken
                    .iter()
                    .chain(placed)
                    .all(|q| q.pos.distance_squared(p) >= min_d2)
            };
            for _ in 0..group.count {
                let mut ok = false;
                for _ in 0..10_000 {
                    let p = Vec2::new(rng.random_range(lo.x..=hi.x), rng.random_range(lo.y..=hi.y));
                    if clear(p, &placed) {
                        placed.push(Pose {
                            pos: p,
                            heading: rng.random_range(-std::f32::consts::PI..std::f32::consts::PI),
                        });
                        ok = true;
                        break;
                    }
                }
                if !ok {
                    return Err(SimError::invalid(
                        format!("{key}.count"),
                        group.count,
                        "could not place the robots without overlap (region too crowded)",
                    ));
                }
            }
            Ok(placed)
        }
    }
}
