//! `colcos._core.Baseline`: the paper's hand-written behaviours as policies over a `VecEnv`.
use crate::errors::{TaskError, to_py};
use crate::vec_env::PyVecEnv;
use colcos_env::baseline::BaselinePolicy;
use numpy::{PyArray1, PyArrayMethods};
use pyo3::prelude::*;
use std::sync::Mutex;

#[pyclass(module = "colcos._core", name = "Baseline")]
pub struct PyBaseline {
    policy: Mutex<BaselinePolicy>,
    out: Vec<f32>,
    shape: [usize; 3],
}

#[pymethods]
impl PyBaseline {
    /// Behaviour `name` (see `colcos.behaviours()`) with `params_json` (a JSON object) for every agent
    /// of `env`.
    #[new]
    #[pyo3(signature = (env, name, params_json=None, seed=0))]
    fn new(
        env: PyRef<'_, PyVecEnv>,
        name: &str,
        params_json: Option<&str>,
        seed: u64,
    ) -> PyResult<Self> {
        let params = match params_json {
            Some(s) => serde_json::from_str(s).map_err(|e| {
                TaskError::new_err(format!("behaviour parameters are not valid JSON: {e}"))
            })?,
            None => serde_json::Value::Null,
        };
        let inner = env.lock();
        let policy = BaselinePolicy::new(&inner.env, name, &params, seed).map_err(to_py)?;
        let s = inner.env.spec();
        let shape = [s.num_envs, s.num_agents, 2];
        Ok(PyBaseline {
            policy: Mutex::new(policy),
            out: vec![0.0; shape.iter().product()],
            shape,
        })
    }

    /// Continuous actions `(E, N, 2)` float32 for the env's current sensor readings.
    fn act<'py>(
        &mut self,
        py: Python<'py>,
        env: PyRef<'py, PyVecEnv>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let inner = env.lock();
        let mut policy = self.policy.lock().unwrap_or_else(|e| e.into_inner());
        policy.act(&inner.env, &mut self.out).map_err(to_py)?;
        Ok(PyArray1::from_slice(py, &self.out)
            .reshape(self.shape)?
            .into_any())
    }
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyBaseline>()
}
