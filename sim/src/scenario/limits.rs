//! Checks that need more than the values themselves: the images on disk, the robots' placement, and
//! bounds on the work and memory a step can take. Each limit is a constant here, named in its error.

use super::Scenario;
use super::spec::{MapSpec, Placement};
use crate::error::{Result, SimError};
use crate::field::{Diffusion, GridParams, GridSpec, StepPlan};
use crate::rng::{self, Stream};
use glam::Vec2;
use rand::RngExt;
use std::collections::HashMap;
use std::path::Path;

/// Most diffusion or wind sub-steps one field may take per step.
pub const MAX_SUBSTEPS: usize = 1_000;
/// Most cells of the field grid (one `f32` buffer of it is 400 MB).
pub const MAX_CELLS: f64 = 1e8;
/// Highest tracker frame rate, Hz.
pub const MAX_TRACKER_RATE_HZ: f32 = 1_000.0;
/// Longest tracker latency, s.
pub const MAX_TRACKER_LATENCY: f32 = 10.0;
/// Most tracked poses waiting for delivery (`rate_hz x latency x robots`), each kept in memory.
pub const MAX_POSES_IN_FLIGHT: f64 = 5e7;
/// Widest and tallest GIF frame, px (8K).
pub const MAX_GIF_SIDE: u32 = 7_680;
/// Most points in one polyline map.
pub const MAX_POLYLINE_POINTS: usize = 100_000;
/// Most cell visits to draw one polyline map (each segment visits the cells of its bounding box).
pub const MAX_MAP_CELL_VISITS: f64 = 1e9;
/// Most pixels of an image map (decoded in full when the world is built).
pub const MAX_IMAGE_PIXELS: u64 = 1 << 26;
/// Most robots in a scenario.
pub const MAX_ROBOTS: usize = 100_000;

/// The grid the world builds, checked against [`MAX_CELLS`]; the memory of one buffer per grid
/// pheromone is reserved fallibly once, so that a machine that cannot hold it gets an error here
/// instead of an aborted run.
pub(super) fn check_grid(sc: &Scenario) -> Result<GridSpec> {
    let s = &sc.spec;
    let grid = GridSpec::covering(sc.arena_size(), s.field.cell);
    let cells = grid.nx as f64 * grid.ny as f64;
    if cells > MAX_CELLS {
        return Err(SimError::invalid(
            "field.cell",
            s.field.cell,
            format!(
                "{cells:.0} cells ({:.1} GB per field buffer) is more than the {MAX_CELLS:.0e} cell limit",
                cells * 4.0 / 1e9
            ),
        ));
    }
    let grids = s
        .pheromones
        .iter()
        .filter(|p| p.model == super::ModelKind::Grid)
        .count();
    let floats = grid.len().saturating_mul(grids.max(1));
    let mut probe: Vec<f32> = Vec::new();
    if probe.try_reserve_exact(floats).is_err() {
        return Err(SimError::invalid(
            "field.cell",
            s.field.cell,
            format!(
                "{grids} grid field(s) of {cells:.0} cells need at least {:.1} GB, which cannot be allocated",
                floats as f64 * 4.0 / 1e9
            ),
        ));
    }
    Ok(grid)
}

/// The sub-steps a step of pheromone `i` runs, as the field plans them ([`StepPlan`]).
pub(super) fn check_substeps(sc: &Scenario, i: usize, grid: &GridSpec) -> Result<()> {
    let p = &sc.spec.pheromones[i];
    let params = GridParams {
        evaporation: p.evaporation.unwrap_or(f32::INFINITY),
        diffusion: p.diffusion,
        scheme: p.scheme,
        wind: Vec2::from(p.wind),
    };
    let Some(plan) = StepPlan::new(grid, &params, sc.spec.dt, &mut 0.0) else {
        return Ok(());
    };
    let cure = "use a larger `field.cell` or a smaller `dt`";
    if let Diffusion::Explicit { substeps: n, .. } | Diffusion::OneSided { substeps: n, .. } =
        plan.diffusion
        && n > MAX_SUBSTEPS
    {
        return Err(SimError::invalid(
            format!("pheromones[{i}].diffusion"),
            p.diffusion,
            format!(
                "with scheme = {} a step needs {n} diffusion sub-steps, more than {MAX_SUBSTEPS}: \
                 {cure}, or scheme = \"implicit\"",
                toml::Value::try_from(p.scheme)
                    .map_or_else(|_| format!("{:?}", p.scheme), |v| v.to_string())
            ),
        ));
    }
    if let Some(w) = plan.wind
        && w.substeps > MAX_SUBSTEPS
    {
        return Err(SimError::invalid(
            format!("pheromones[{i}].wind"),
            format!("{:?}", p.wind),
            format!(
                "a step needs {} wind sub-steps, more than {MAX_SUBSTEPS}: {cure}",
                w.substeps
            ),
        ));
    }
    Ok(())
}

/// A polyline map's point count and drawing work (as `polyline_map` visits cells).
pub(super) fn check_polyline(key: &str, map: &MapSpec, grid: &GridSpec) -> Result<()> {
    let Some(points) = &map.polyline else {
        return Ok(());
    };
    if points.len() > MAX_POLYLINE_POINTS {
        return Err(SimError::invalid(
            format!("{key}.polyline"),
            format!("{} points", points.len()),
            format!("more than {MAX_POLYLINE_POINTS} points"),
        ));
    }
    let half = 0.5 * map.width.unwrap_or(0.0).max(0.0);
    let visits: f64 = points
        .windows(2)
        .map(|w| {
            let (a, b) = (w[0], w[1]);
            let (i0, i1) = grid.cell_range(a[0].min(b[0]) - half, a[0].max(b[0]) + half, grid.nx);
            let (j0, j1) = grid.cell_range(a[1].min(b[1]) - half, a[1].max(b[1]) + half, grid.ny);
            (i1 - i0) as f64 * (j1 - j0) as f64
        })
        .sum();
    if visits > MAX_MAP_CELL_VISITS {
        return Err(SimError::invalid(
            format!("{key}.polyline"),
            format!("{} points", points.len()),
            format!(
                "drawing it (width {} m) visits {visits:.0} cells, more than {MAX_MAP_CELL_VISITS:.0e}",
                2.0 * half
            ),
        ));
    }
    Ok(())
}

/// Opens an image map and reads its header: a file that is missing, a directory, not a PNG or too
/// large is refused now, as the world build would refuse it (only the pixel data is left unread).
pub(super) fn check_image(key: &str, image: &str, base_dir: &Path) -> Result<()> {
    let key = format!("{key}.image");
    let path = base_dir.join(image);
    let bad = |reason: String| SimError::invalid(&key, format!("{image:?}"), reason);
    let shown = path.display();
    let meta = std::fs::metadata(&path).map_err(|e| bad(format!("cannot open {shown}: {e}")))?;
    if !meta.is_file() {
        return Err(bad(format!("{shown} is not a file")));
    }
    let reader = image::ImageReader::open(&path)
        .and_then(|r| r.with_guessed_format())
        .map_err(|e| bad(format!("cannot read {shown}: {e}")))?;
    if reader.format() != Some(image::ImageFormat::Png) {
        return Err(bad(format!("{shown} is not a PNG image")));
    }
    let (w, h) = reader
        .into_dimensions()
        .map_err(|e| bad(format!("{shown} is not a readable PNG: {e}")))?;
    if w == 0 || h == 0 {
        return Err(bad(format!("{shown} is empty ({w} x {h} px)")));
    }
    if u64::from(w) * u64::from(h) > MAX_IMAGE_PIXELS {
        return Err(bad(format!(
            "{shown} is {w} x {h} px, more than {MAX_IMAGE_PIXELS} pixels"
        )));
    }
    Ok(())
}

/// Robots already placed, bucketed by position so that a placement try looks at its neighbours only.
/// Buckets are a little wider than the largest distance asked for, so no closer robot is missed.
struct Placed {
    side: f32,
    buckets: HashMap<(i64, i64), Vec<(Vec2, usize)>>,
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

/// Runs the placement the world runs for world 0 (`colcos run`; `World::new`), drawing the same
/// numbers from the same stream, so that a scenario that validates also places. It mirrors the
/// world's placement (private to the world) step for step; `scenario_limits` tests pin the two
/// together. Robots closer than a diameter to an earlier one (explicit or grid) are refused too.
pub(super) fn check_placement(sc: &Scenario) -> Result<()> {
    let s = &sc.spec;
    let arena = sc.arena_size();
    let radius = s.robot.radius;
    let gap = 0.002;
    let min_d2 = (2.0 * radius + gap).powi(2);
    let diameter2 = (2.0 * radius).powi(2);
    let mut placed = Placed {
        side: (2.0 * radius + gap) * 1.01,
        buckets: HashMap::new(),
    };
    let mut rng = rng::stream_of(s.seed, 0, Stream::Placement);
    let heading = |rng: &mut rng::SimRng| -> f32 {
        rng.random_range(-std::f32::consts::PI..std::f32::consts::PI)
    };
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
                    placed.push(pos, g);
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
                    heading(&mut rng);
                    if let Some(q) = placed.closer(pos, diameter2) {
                        return Err(overlap(key, pos, q));
                    }
                    new.push(pos);
                }
                new.into_iter().for_each(|p| placed.push(p, g));
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
                        if placed.closer(p, min_d2).is_none() {
                            heading(&mut rng);
                            placed.push(p, g);
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
    Ok(())
}

/// Most grid cells all deposits together may touch in one step (each robot's kernel box, per deposit).
pub const MAX_DEPOSIT_CELLS: f64 = 1e9;
/// Most (robot, Gaussian source) pairs a step may evaluate (every robot senses every source).
pub const MAX_SOURCE_PAIRS: f64 = 1e9;

/// The cells a step of deposits touches and the robot-source pairs it evaluates, both summed over
/// the groups: the first group to cross a limit is named.
pub(super) fn check_step_work(sc: &Scenario, grid: &GridSpec) -> Result<()> {
    let s = &sc.spec;
    let robots = sc.robot_count() as f64;
    let mut sources: f64 = s.pheromones.iter().map(|p| p.sources.len() as f64).sum();
    let mut cells = 0.0f64;
    let side =
        |support: f32, n: usize| ((2.0 * support / grid.cell).ceil() as f64 + 2.0).min(n as f64);
    for (g, group) in s.robots.iter().enumerate() {
        for (d, dep) in group.deposits.iter().enumerate() {
            let support = dep.kernel.support();
            cells += group.count as f64 * side(support, grid.nx) * side(support, grid.ny);
            if cells > MAX_DEPOSIT_CELLS {
                return Err(SimError::invalid(
                    format!("robots[{g}].deposits[{d}].kernel"),
                    format!("{:?}", dep.kernel),
                    format!(
                        "the deposits would touch {cells:.0} cells a step, more than {MAX_DEPOSIT_CELLS:.0e}"
                    ),
                ));
            }
        }
        sources += group.count as f64 * group.emits.len() as f64;
        if sources * robots > MAX_SOURCE_PAIRS {
            return Err(SimError::invalid(
                format!("robots[{g}].emits"),
                group.emits.len(),
                format!(
                    "{robots} robots sensing {sources} Gaussian sources is {:.0} pairs a step, more than {MAX_SOURCE_PAIRS:.0e}",
                    sources * robots
                ),
            ));
        }
    }
    Ok(())
}
