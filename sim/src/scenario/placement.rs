//! Initial robot placement: random without overlap, on a grid, or explicit. One function for the
//! world that places and for the validation that must refuse what would not place.
use super::Scenario;
use super::spec::Placement;
use crate::arena::Obstacles;
use crate::error::{Result, SimError};
use crate::rng::SimRng;
use crate::robot::Pose;
use glam::Vec2;
use rand::RngExt;
use std::collections::HashMap;

/// Robots already placed, bucketed by position so that a placement try looks at its neighbours only.
/// Buckets are a little wider than the largest distance asked for, so no closer robot is missed.
struct Placed {
    side: f32,
    /// foldhash, not std's SipHash: a placement try looks up nine buckets, and SipHash made them
    /// most of a small world's placement.
    buckets: HashMap<(i64, i64), Vec<(Vec2, usize)>, foldhash::fast::FixedState>,
}

impl Placed {
    fn bucket(&self, p: Vec2) -> (i64, i64) {
        (
            (p.x / self.side).floor() as i64,
            (p.y / self.side).floor() as i64,
        )
    }
    fn push(&mut self, p: Vec2, group: usize) {
        let b = self.bucket(p);
        self.buckets.entry(b).or_default().push((p, group));
    }
    /// The group of a placed robot closer than `sqrt(d2)` to `p` (`d2 <= side^2`), if any.
    fn closer(&self, p: Vec2, d2: f32) -> Option<(Vec2, usize)> {
        let (bx, by) = self.bucket(p);
        (bx - 1..=bx + 1)
            .flat_map(|x| (by - 1..=by + 1).map(move |y| (x, y)))
            .filter_map(|b| self.buckets.get(&b))
            .flatten()
            .find(|(q, _)| q.distance_squared(p) < d2)
            .copied()
    }
}

/// Every robot's start pose, groups in order, drawn from `rng` (the world's placement stream): random
/// without overlap, on a grid, or explicit. Robots closer than a diameter to an earlier one (explicit
/// or grid) and groups that cannot be placed are errors naming the key. Validation runs this for
/// world 0, the world builds with it, so a scenario that validates also places. `obstacles` are the
/// scenario's ([`super::Scenario::obstacles`], built once by the caller, who keeps them).
pub(crate) fn place(sc: &Scenario, obstacles: &Obstacles, rng: &mut SimRng) -> Result<Vec<Pose>> {
    let s = &sc.spec;
    // Robots start clear of the obstacles: explicit and grid poses inside one are errors, random
    // placement draws again.
    let inside = |key: String, p: Vec2| -> Result<()> {
        let what = match obstacles.overlapping(p, s.robot.radius, 0.0) {
            Some(o) => match s.obstacles.get(o) {
                Some(ob) => format!("overlaps obstacles[{o}] ({:?})", ob.shape),
                None => "overlaps the arena's boundary (arena.shape)".to_string(),
            },
            None if !obstacles.holds(p, s.robot.radius) => {
                "lies outside the arena's shape (arena.shape)".to_string()
            }
            None => return Ok(()),
        };
        Err(SimError::invalid(
            key,
            format!("[{}, {}]", p.x, p.y),
            format!("a robot of radius {} m there {what}", s.robot.radius),
        ))
    };
    let arena = sc.arena_size();
    let radius = s.robot.radius;
    let gap = 0.002;
    let min_d2 = (2.0 * radius + gap).powi(2);
    let diameter2 = (2.0 * radius).powi(2);
    let mut placed = Placed {
        side: (2.0 * radius + gap) * 1.01,
        buckets: HashMap::default(),
    };
    let mut poses = Vec::with_capacity(sc.robot_count());
    let heading =
        |rng: &mut SimRng| -> f32 { rng.random_range(-std::f32::consts::PI..std::f32::consts::PI) };
    let overlap = |key: String, p: Vec2, (q, h): (Vec2, usize)| {
        SimError::invalid(
            key,
            format!("[{}, {}]", p.x, p.y),
            format!(
                "closer than a robot diameter ({} m) to a robot of robots[{h}] at [{}, {}]{}",
                2.0 * radius,
                q.x,
                q.y,
                " (random placement avoids only the groups listed before it)"
            ),
        )
    };
    for (g, group) in s.robots.iter().enumerate() {
        let key = format!("robots[{g}].placement");
        let region = group.region.unwrap_or([0.0, 0.0, arena.x, arena.y]);
        let (lo, hi) = (
            Vec2::new(region[0].max(radius + gap), region[1].max(radius + gap)),
            Vec2::new(
                region[2].min(arena.x - radius - gap),
                region[3].min(arena.y - radius - gap),
            ),
        );
        match group.placement {
            Placement::Explicit => {
                for (n, p) in group.poses.iter().enumerate() {
                    let pos = Vec2::new(p[0], p[1]);
                    if let Some(q) = placed.closer(pos, diameter2) {
                        return Err(overlap(format!("robots[{g}].poses[{n}]"), pos, q));
                    }
                    inside(format!("robots[{g}].poses[{n}]"), pos)?;
                    placed.push(pos, g);
                    poses.push(Pose::new(p[0], p[1], p[2].to_radians()));
                }
            }
            Placement::Grid => {
                let n = group.count;
                let size = hi - lo;
                let cols = ((n as f32 * size.x / size.y.max(1e-9)).sqrt().ceil() as usize)
                    .clamp(1, n.max(1));
                let rows = n.div_ceil(cols);
                let step = Vec2::new(size.x / cols as f32, size.y / rows.max(1) as f32);
                if step.min_element() < 2.0 * radius {
                    return Err(SimError::invalid(
                        key,
                        "\"grid\"",
                        format!(
                            "{n} robots on a {cols} x {rows} grid in region {region:?} are closer than a diameter"
                        ),
                    ));
                }
                let mut new = Vec::with_capacity(n);
                for k in 0..n {
                    let (c, r) = (k % cols, k / cols);
                    let pos = lo + Vec2::new((c as f32 + 0.5) * step.x, (r as f32 + 0.5) * step.y);
                    let heading = heading(rng);
                    if let Some(q) = placed.closer(pos, diameter2) {
                        return Err(overlap(key, pos, q));
                    }
                    inside(key.clone(), pos)?;
                    new.push(Pose { pos, heading });
                }
                new.iter().for_each(|p| placed.push(p.pos, g));
                poses.extend(new);
            }
            Placement::Random => {
                if !(lo.x <= hi.x && lo.y <= hi.y) {
                    return Err(SimError::invalid(
                        key,
                        "\"random\"",
                        format!(
                            "region {region:?} leaves no room for a robot {gap} m clear of the walls"
                        ),
                    ));
                }
                for k in 0..group.count {
                    let mut ok = false;
                    for _ in 0..10_000 {
                        let p =
                            Vec2::new(rng.random_range(lo.x..=hi.x), rng.random_range(lo.y..=hi.y));
                        if placed.closer(p, min_d2).is_none()
                            && obstacles.overlapping(p, radius + gap, 0.0).is_none()
                            && obstacles.holds(p, radius + gap)
                        {
                            let heading = heading(rng);
                            placed.push(p, g);
                            poses.push(Pose { pos: p, heading });
                            ok = true;
                            break;
                        }
                    }
                    if !ok {
                        return Err(SimError::invalid(
                            key,
                            "\"random\"",
                            format!(
                                "robot {} of {} found no free spot in 10000 tries (seed {}): \
                                 region {region:?} is too crowded",
                                k + 1,
                                group.count,
                                s.seed
                            ),
                        ));
                    }
                }
            }
        }
    }
    Ok(poses)
}
