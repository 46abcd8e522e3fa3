//! `colcos._core.Baseline`: the paper's hand-written behaviours as policies over a `VecEnv`.
//! Locks are taken with the GIL released, the env's before the policy's (one order, no deadlock).
use crate::args::{self, guard};
use crate::errors::{Kind, to_py};
use crate::vec_env::PyVecEnv;
use colcos_env::baseline::BaselinePolicy;
use numpy::{PyArray1, PyArrayMethods};
use pyo3::prelude::*;
use std::sync::Mutex;

struct State {
    policy: BaselinePolicy,
    out: Vec<f32>,
}

#[pyclass(module = "colcos._core", name = "Baseline", frozen)]
pub struct PyBaseline {
    state: Mutex<State>,
    shape: [usize; 3],
}

#[pymethods]
impl PyBaseline {
    /// Behaviour `name` (see `colcos.behaviours()`) with `params_json` (a JSON object), or a task's
    /// own policy (`colcos.task_policies()`), for every agent of `env`.
    #[new]
    #[pyo3(signature = (env, name, params_json=None, seed=None))]
    fn new(
        py: Python<'_>,
        env: &Bound<'_, PyAny>,
        name: &Bound<'_, PyAny>,
        params_json: Option<&Bound<'_, PyAny>>,
        seed: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        guard(|| {
            let env = env_of(env)?;
            let name = args::text(name, "name")?;
            let params = match args::opt_text(params_json, "params_json")? {
                Some(s) => serde_json::from_str(&s).map_err(|e| {
                    Kind::Task.err(format!("behaviour parameters are not valid JSON: {e}"))
                })?,
                None => serde_json::Value::Null,
            };
            let seed = match seed.filter(|s| !s.is_none()) {
                Some(s) => args::seed(s, "seed")?,
                None => 0,
            };
            let me: &PyVecEnv = env.get();
            let (policy, shape) = py
                .detach(|| {
                    let g = me.lock();
                    let s = g.env.spec();
                    BaselinePolicy::new(&g.env, &name, &params, seed)
                        .map(|p| (p.width(), p))
                        .map(|(w, p)| (p, [s.num_envs, s.num_agents, w]))
                })
                .map_err(to_py)?;
            Ok(PyBaseline {
                state: Mutex::new(State {
                    policy,
                    out: vec![0.0; shape.iter().product()],
                }),
                shape,
            })
        })
    }

    /// Continuous actions `(E, N, 2 + D)` float32 for the env's current sensor readings (wheels, then
    /// the deposit rates: 0 for a sim behaviour, chosen by a task's own policy).
    fn act<'py>(&self, py: Python<'py>, env: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyAny>> {
        guard(|| {
            let env = env_of(env)?;
            let me: &PyVecEnv = env.get();
            let out = py
                .detach(|| {
                    let g = me.lock();
                    let mut st = self.state.lock().unwrap_or_else(|e| e.into_inner());
                    let State { policy, out } = &mut *st;
                    let s = g.env.spec();
                    if out.len() != s.num_envs * s.num_agents * g.env.action_decoder().width() {
                        return Err(colcos_env::EnvError::State(
                            "this policy was made for another environment (its sizes differ)"
                                .into(),
                        ));
                    }
                    policy.act(&g.env, out).map(|()| out.clone())
                })
                .map_err(to_py)?;
            Ok(PyArray1::from_vec(py, out).reshape(self.shape)?.into_any())
        })
    }
}

fn env_of<'a, 'py>(env: &'a Bound<'py, PyAny>) -> PyResult<&'a Bound<'py, PyVecEnv>> {
    env.cast::<PyVecEnv>().map_err(|_| {
        Kind::ArgumentType.err(format!(
            "env must be a colcos._core.VecEnv, got {}",
            args::show(env)
        ))
    })
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyBaseline>()
}
