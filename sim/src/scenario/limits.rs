//! Checks that need more than the values themselves: the images on disk and bounds on the work and
//! memory a step can take. Each limit is a constant here, named in its error.

use super::Scenario;
use super::spec::MapSpec;
use crate::error::{Result, SimError};
use crate::field::{Diffusion, GridParams, GridSpec, StepPlan};
use glam::Vec2;
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
    let MapSpec::Polyline {
        polyline: points,
        width,
        ..
    } = map
    else {
        return Ok(());
    };
    if points.len() > MAX_POLYLINE_POINTS {
        return Err(SimError::invalid(
            format!("{key}.polyline"),
            format!("{} points", points.len()),
            format!("more than {MAX_POLYLINE_POINTS} points"),
        ));
    }
    let half = 0.5 * width.max(0.0);
    let visits: f64 = points
        .windows(2)
        .map(|w| {
            let (a, b) = (Vec2::from(w[0]), Vec2::from(w[1]));
            let ((i0, i1), (j0, j1)) = grid.segment_cells(a, b, half);
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
        let trails = (group.deposits.iter().map(|d| ("deposits", d.kernel))).chain(
            group
                .deposit_actions
                .iter()
                .map(|d| ("deposit_actions", d.kernel)),
        );
        for (d, (list, kernel)) in trails.enumerate() {
            let d = if list == "deposits" {
                d
            } else {
                d - group.deposits.len()
            };
            let support = kernel.support();
            cells += group.count as f64 * side(support, grid.nx) * side(support, grid.ny);
            if cells > MAX_DEPOSIT_CELLS {
                let (name, size) = match kernel {
                    crate::field::Kernel::Disc { radius }
                    | crate::field::Kernel::Cone { radius } => ("radius", radius),
                    crate::field::Kernel::Gaussian { sigma } => ("sigma", sigma),
                };
                return Err(SimError::invalid(
                    format!("robots[{g}].{list}[{d}].kernel.{name}"),
                    size,
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
