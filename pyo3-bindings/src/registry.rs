//! What exists: tasks, behaviours, default scenarios.
use crate::errors::{TaskError, to_py};
use pyo3::prelude::*;

/// `[(name, description)]` of every task.
#[pyfunction]
fn tasks() -> Vec<(&'static str, &'static str)> {
    colcos_env::task::registry::list().collect()
}

/// `[(name, description)]` of every hand-written behaviour (usable as baseline policies).
#[pyfunction]
fn behaviours() -> Vec<(&'static str, &'static str)> {
    colcos_sim::behaviour::registry::list().collect()
}

/// `[(key, type, default, meaning)]` of every key of behaviour `name`'s `params` table.
#[pyfunction]
fn behaviour_params(
    name: &str,
) -> PyResult<Vec<(&'static str, &'static str, &'static str, &'static str)>> {
    let docs = colcos_sim::behaviour::registry::params(name).ok_or_else(|| {
        let known: Vec<_> = colcos_sim::behaviour::registry::list()
            .map(|(n, _)| n)
            .collect();
        TaskError::new_err(format!("unknown behaviour {name:?} (known: {known:?})"))
    })?;
    Ok(docs
        .iter()
        .map(|d| (d.name, d.ty, d.default, d.meaning))
        .collect())
}

/// The built-in scenario (TOML text) of a task.
#[pyfunction]
fn default_scenario(task: &str) -> PyResult<&'static str> {
    colcos_env::task::registry::default_scenario(task).map_err(to_py)
}

/// Names of the observation vector's entries.
#[pyfunction]
fn observation_names() -> Vec<&'static str> {
    colcos_env::encoding::OBS_NAMES.to_vec()
}

/// The discrete actions as (left, right) fractions of the largest wheel speed.
#[pyfunction]
fn discrete_actions() -> Vec<(f32, f32)> {
    colcos_env::encoding::DISCRETE_ACTIONS.to_vec()
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(tasks, m)?)?;
    m.add_function(wrap_pyfunction!(behaviours, m)?)?;
    m.add_function(wrap_pyfunction!(behaviour_params, m)?)?;
    m.add_function(wrap_pyfunction!(default_scenario, m)?)?;
    m.add_function(wrap_pyfunction!(observation_names, m)?)?;
    m.add_function(wrap_pyfunction!(discrete_actions, m)?)?;
    Ok(())
}
