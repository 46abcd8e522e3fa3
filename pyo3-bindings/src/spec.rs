//! The environment's spec as a Python dict: sizes, names and spaces, with per-entry bounds where the
//! values take tighter ones than the box's envelope.
use colcos_env::{EnvSpec, Space};
use pyo3::prelude::*;
use pyo3::types::PyDict;

fn space_dict<'py>(
    py: Python<'py>,
    space: &Space,
    bounds: Option<(Vec<f32>, Vec<f32>)>,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    match space {
        Space::Box {
            low,
            high,
            shape,
            dtype,
        } => {
            d.set_item("kind", "box")?;
            match bounds {
                Some((lo, hi)) => {
                    d.set_item("low", lo)?;
                    d.set_item("high", hi)?;
                }
                None => {
                    d.set_item("low", low)?;
                    d.set_item("high", high)?;
                }
            }
            d.set_item("shape", shape.clone())?;
            d.set_item("dtype", dtype)?;
        }
        Space::Discrete { n } => {
            d.set_item("kind", "discrete")?;
            d.set_item("n", n)?;
        }
    }
    Ok(d)
}

/// The spec dict of `VecEnv.spec()`.
pub fn spec_dict<'py>(
    py: Python<'py>,
    s: &EnvSpec,
    autoreset: &str,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("task", &s.task)?;
    d.set_item("env_name", &s.env_name)?;
    d.set_item("num_envs", s.num_envs)?;
    d.set_item("num_agents", s.num_agents)?;
    d.set_item("num_robots", s.num_robots)?;
    d.set_item("agent_names", s.agent_names.clone())?;
    d.set_item("agent_robots", s.agent_robots.clone())?;
    d.set_item(
        "observation",
        space_dict(py, &s.observation, Some(s.observation_bounds()))?,
    )?;
    d.set_item("action", space_dict(py, &s.action, s.action_bounds())?)?;
    d.set_item(
        "state",
        s.state
            .as_ref()
            .map(|x| space_dict(py, x, s.state_bounds()))
            .transpose()?,
    )?;
    d.set_item(
        "patch",
        s.patch
            .as_ref()
            .map(|x| space_dict(py, x, None))
            .transpose()?,
    )?;
    d.set_item("max_cycles", s.max_cycles)?;
    d.set_item("dt", s.dt)?;
    d.set_item("autoreset_mode", autoreset)?;
    Ok(d)
}
