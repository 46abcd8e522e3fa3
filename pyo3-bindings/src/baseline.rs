//! `colcos._core.Baseline`: the paper's hand-written behaviours as policies over a `VecEnv` or a
//! `Plant` (a twin, the rig). Locks are taken with the GIL released, the env's before the policy's
//! (one order, no deadlock).
use crate::arena_io::shaped;
use crate::args::{self, guard};
use crate::errors::{Kind, to_py};
use crate::plant::PyPlant;
use crate::vec_env::PyVecEnv;
use colcos_env::EnvError;
use colcos_env::baseline::{Arenas, BaselinePolicy};
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
            let (policy, shape) = with_arenas(py, env, |a| {
                let s = a.spec();
                BaselinePolicy::new(a, &name, &params, seed)
                    .map(|p| (p.width(), p))
                    .map(|(w, p)| (p, [s.num_envs, s.num_agents, w]))
            })?;
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
            let out = with_arenas(py, env, |a| {
                let mut st = self.state.lock().unwrap_or_else(|e| e.into_inner());
                let State { policy, out } = &mut *st;
                let s = a.spec();
                if out.len() != s.num_envs * s.num_agents * a.action_width() {
                    return Err(EnvError::State(
                        "this policy was made for another environment (its sizes differ)".into(),
                    ));
                }
                policy.act(a, out).map(|()| out.clone())
            })?;
            shaped(py, out, self.shape)
        })
    }
}

/// `f` on the arenas of `env` (a `VecEnv` or a `Plant`), under its lock with the GIL released.
fn with_arenas<R: Send>(
    py: Python<'_>,
    env: &Bound<'_, PyAny>,
    f: impl FnOnce(&dyn Arenas) -> Result<R, EnvError> + Send,
) -> PyResult<R> {
    if let Ok(venv) = env.cast::<PyVecEnv>() {
        let me: &PyVecEnv = venv.get();
        return py.detach(|| f(&me.lock().env)).map_err(to_py);
    }
    if let Ok(plant) = env.cast::<PyPlant>() {
        let me: &PyPlant = plant.get();
        return py.detach(|| f(&*me.lock())).map_err(to_py);
    }
    Err(Kind::ArgumentType.err(format!(
        "env must be a colcos._core.VecEnv or a colcos._core.Plant, got {}",
        args::show(env)
    )))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyBaseline>()
}
