//! What exists: tasks, behaviours, default scenarios.
use crate::args::{self, guard};
use crate::errors::{Kind, to_py};
use pyo3::prelude::*;

/// `[(name, description)]` of every task.
#[pyfunction]
fn tasks() -> PyResult<Vec<(&'static str, &'static str)>> {
    guard(|| Ok(colcos_env::task::registry::list().collect()))
}

/// `[(name, description)]` of every hand-written behaviour (usable as baseline policies).
#[pyfunction]
fn behaviours() -> PyResult<Vec<(&'static str, &'static str)>> {
    guard(|| Ok(colcos_sim::behaviour::registry::list().collect()))
}

/// `[(name, task, description)]` of every task's own hand-written policy (wheels and deposit rates,
/// from the agent's observation row; usable as baseline policies).
#[pyfunction]
fn task_policies() -> PyResult<Vec<(&'static str, &'static str, &'static str)>> {
    guard(|| Ok(colcos_env::policy::POLICIES.to_vec()))
}

/// `[(key, type, default, meaning)]` of every key of behaviour `name`'s `params` table.
#[pyfunction]
fn behaviour_params(
    name: &Bound<'_, PyAny>,
) -> PyResult<Vec<(&'static str, &'static str, &'static str, &'static str)>> {
    guard(|| {
        let name = args::text(name, "name")?;
        let docs = colcos_sim::behaviour::registry::params(&name).ok_or_else(|| {
            let known: Vec<_> = colcos_sim::behaviour::registry::list()
                .map(|(n, _)| n)
                .collect();
            Kind::Task.err(format!("unknown behaviour {name:?} (known: {known:?})"))
        })?;
        Ok(docs
            .iter()
            .map(|d| (d.name, d.ty, d.default, d.meaning))
            .collect())
    })
}

/// The built-in scenario (TOML text) of a task.
#[pyfunction]
fn default_scenario(task: &Bound<'_, PyAny>) -> PyResult<&'static str> {
    guard(|| {
        let task = args::text(task, "task")?;
        colcos_env::task::registry::default_scenario(&task).map_err(to_py)
    })
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

/// Panics with `msg` under the guard every entry point runs under: the tests' way to check that a
/// Rust panic reaches Python as `colcos.InternalError`, never as `PanicException`.
#[pyfunction]
fn _test_panic(msg: &Bound<'_, PyAny>) -> PyResult<()> {
    guard(|| {
        let msg = args::text(msg, "msg")?;
        panic!("{msg}")
    })
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(_test_panic, m)?)?;
    m.add_function(wrap_pyfunction!(tasks, m)?)?;
    m.add_function(wrap_pyfunction!(behaviours, m)?)?;
    m.add_function(wrap_pyfunction!(task_policies, m)?)?;
    m.add_function(wrap_pyfunction!(behaviour_params, m)?)?;
    m.add_function(wrap_pyfunction!(default_scenario, m)?)?;
    m.add_function(wrap_pyfunction!(observation_names, m)?)?;
    m.add_function(wrap_pyfunction!(discrete_actions, m)?)?;
    Ok(())
}
