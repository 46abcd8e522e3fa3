//! Bounds on what one call from Python may ask of the machine, each named in its error: a size that
//! is a valid number but cannot be held raises a `colcos.TaskError` instead of aborting the
//! interpreter on a failed allocation.
use colcos_env::{EnvConfig, EnvError};
use colcos_sim::field::GridSpec;
use colcos_sim::scenario::ModelKind;

/// Most worlds in one batch.
pub const MAX_NUM_ENVS: u64 = 1 << 16;
/// Most worker threads (as `colcos run --threads`).
pub const MAX_THREADS: u64 = 1_024;
/// Longest episode, steps (a year and a half at 50 steps a second).
pub const MAX_CYCLES: u64 = 1 << 31;
/// Widest rendered image, px (8K, as the CLI's GIF frames); the height follows the screen's aspect.
pub const MAX_RENDER_WIDTH: u64 = 7_680;
/// Most pixels of a rendered image (an 8K square).
pub const MAX_RENDER_PIXELS: u64 = 7_680 * 7_680;
/// Widest egocentric patch, px.
pub const MAX_PATCH_PIXELS: u64 = 256;
/// Largest magnitude of a task parameter: with reward weights below it every reward stays finite in
/// `f32` (each term of a built-in task's reward is at most a few units before its weight).
pub const MAX_PARAM_MAGNITUDE: f64 = 1e9;
/// Most memory the worlds of one batch may take (estimated before they are built), bytes.
pub const MAX_BATCH_BYTES: u64 = 64 << 30;

/// Every number in the task parameters is finite and within [`MAX_PARAM_MAGNITUDE`]; `path` names
/// the key (`progress_weight`, `food[0][1]`).
pub fn check_params(path: &str, v: &serde_json::Value) -> Result<(), String> {
    match v {
        serde_json::Value::Number(n) => {
            let x = n.as_f64().unwrap_or(f64::INFINITY);
            if x.abs() > MAX_PARAM_MAGNITUDE {
                return Err(format!(
                    "task parameter `{path}` = {n} is beyond the limit of {MAX_PARAM_MAGNITUDE:e} in \
                     magnitude (rewards would not stay finite)"
                ));
            }
            Ok(())
        }
        serde_json::Value::Array(items) => items
            .iter()
            .enumerate()
            .try_for_each(|(i, x)| check_params(&format!("{path}[{i}]"), x)),
        serde_json::Value::Object(map) => map.iter().try_for_each(|(k, x)| {
            let key = if path.is_empty() {
                k.clone()
            } else {
                format!("{path}.{k}")
            };
            check_params(&key, x)
        }),
        _ => Ok(()),
    }
}

/// The memory the batch of `cfg` will take, estimated from its scenario, is bounded and can be
/// allocated (tried fallibly, then given back).
pub fn check_batch_memory(cfg: &EnvConfig) -> Result<(), EnvError> {
    let default = colcos_env::task::registry::default_scenario(&cfg.task)?;
    let sc = cfg.scenario.load(default)?;
    let grid = GridSpec::covering(sc.arena_size(), sc.spec.field.cell);
    let grids = sc
        .spec
        .pheromones
        .iter()
        .filter(|p| p.model == ModelKind::Grid)
        .count() as u64;
    let cells = (grid.nx as u64).saturating_mul(grid.ny as u64);
    let robots = sc.robot_count() as u64;
    let patch = cfg
        .patch
        .map_or(0, |p| (p.pixels as u64).pow(2).saturating_mul(3));
    // A grid pheromone keeps a few f32 buffers of the grid; the screen and scratch a few more.
    let world = cells
        .saturating_mul(4 * (4 * grids + 2))
        .saturating_add(robots.saturating_mul(4_096 + patch))
        .saturating_add(64 << 10);
    let total = world.saturating_mul(cfg.num_envs as u64);
    let gib = |b: u64| b as f64 / (1u64 << 30) as f64;
    if total > MAX_BATCH_BYTES {
        return Err(EnvError::param(
            "num_envs",
            format!(
                "{}: the batch would take about {:.1} GiB ({:.2} MiB per world), more than the \
             {:.0} GiB limit; use fewer worlds (or a coarser field.cell, a smaller patch)",
                cfg.num_envs,
                gib(total),
                world as f64 / (1u64 << 20) as f64,
                gib(MAX_BATCH_BYTES)
            ),
        ));
    }
    let mut probe: Vec<u8> = Vec::new();
    if probe.try_reserve_exact(total as usize).is_err() {
        return Err(EnvError::param(
            "num_envs",
            format!(
                "{}: the batch needs about {:.1} GiB, which cannot be allocated here; use fewer \
                 worlds",
                cfg.num_envs,
                gib(total)
            ),
        ));
    }
    Ok(())
}

/// `colcos._core.LIMITS`: the bounds above, for the Python faces' own checks and messages.
pub fn register(m: &pyo3::Bound<'_, pyo3::types::PyModule>) -> pyo3::PyResult<()> {
    use pyo3::types::PyModuleMethods;
    let d = pyo3::types::PyDict::new(m.py());
    use pyo3::types::PyDictMethods;
    d.set_item("num_envs", MAX_NUM_ENVS)?;
    d.set_item("num_threads", MAX_THREADS)?;
    d.set_item("max_cycles", MAX_CYCLES)?;
    d.set_item("render_width", MAX_RENDER_WIDTH)?;
    d.set_item("patch", MAX_PATCH_PIXELS)?;
    d.set_item("param_magnitude", MAX_PARAM_MAGNITUDE)?;
    d.set_item("batch_bytes", MAX_BATCH_BYTES)?;
    m.add("LIMITS", d)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn params_name_the_key_beyond_the_limit() {
        let ok = serde_json::json!({"progress_weight": 2.0, "food": [[1.3, 0.5]]});
        assert!(check_params("", &ok).is_ok());
        let bad = serde_json::json!({"food": [[1.3, 1e12]]});
        let e = check_params("", &bad).unwrap_err();
        assert!(e.contains("`food[0][1]`"), "{e}");
        let bad = serde_json::json!({"alarm_weight": -1e30});
        assert!(check_params("", &bad).unwrap_err().contains("alarm_weight"));
    }
}
