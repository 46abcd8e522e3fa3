//! `colcos._core.VecEnv`: the batched environment, its buffers handed to Python as numpy views.
use crate::errors::{ActionError, TaskError, to_py};
use colcos_env::{
    ActionKind, Actions, AutoresetMode, EnvConfig, PatchConfig, ScenarioSource, Space, VecEnv,
};
use numpy::ndarray::{ArrayView, IxDyn};
use numpy::{
    Element, PyArray, PyArray1, PyArrayMethods, PyReadonlyArrayDyn, PyUntypedArrayMethods,
};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::sync::Mutex;

/// The environment and its action scratch buffers. Behind a mutex because pyo3 classes must be
/// `Sync` (behaviours and field backends are `Send` only); every call takes it once.
pub(crate) struct Inner {
    pub env: VecEnv,
    actions_f: Vec<f32>,
    actions_i: Vec<i64>,
}

#[pyclass(module = "colcos._core", name = "VecEnv")]
pub struct PyVecEnv {
    pub(crate) inner: Mutex<Inner>,
}

impl PyVecEnv {
    pub(crate) fn lock(&self) -> std::sync::MutexGuard<'_, Inner> {
        // A panic while holding the lock cannot leave the env half-stepped in a way Python could see
        // differently from an error; keep going with the data.
        self.inner.lock().unwrap_or_else(|e| e.into_inner())
    }
}

fn space_dict<'py>(py: Python<'py>, space: &Space) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    match space {
        Space::Box {
            low,
            high,
            shape,
            dtype,
        } => {
            d.set_item("kind", "box")?;
            d.set_item("low", low)?;
            d.set_item("high", high)?;
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

/// A numpy view of `len` elements at `ptr` shaped `shape`, keeping `owner` alive.
///
/// # Safety
/// `ptr..ptr + product(shape)` must stay valid for as long as `owner` lives.
unsafe fn view<'py, T: Element>(
    owner: &Bound<'py, PyAny>,
    ptr: *mut T,
    shape: Vec<usize>,
) -> PyResult<Bound<'py, PyAny>> {
    let a = unsafe { ArrayView::from_shape_ptr(IxDyn(&shape), ptr as *const T) };
    Ok(unsafe { PyArray::borrow_from_array(&a, owner.clone()) }.into_any())
}

#[pymethods]
impl PyVecEnv {
    #[new]
    #[pyo3(signature = (task, num_envs=1, seed=0, num_threads=None, scenario=None, scenario_text=None, max_cycles=0, action="continuous", autoreset_mode="next_step", global_state=true, patch_pixels=None, patch_side=0.08, params_json=None, backend=None))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        task: &str,
        num_envs: usize,
        seed: u64,
        num_threads: Option<usize>,
        scenario: Option<std::path::PathBuf>,
        scenario_text: Option<String>,
        max_cycles: u64,
        action: &str,
        autoreset_mode: &str,
        global_state: bool,
        patch_pixels: Option<usize>,
        patch_side: f32,
        params_json: Option<&str>,
        backend: Option<&str>,
        py: Python<'_>,
    ) -> PyResult<Self> {
        let mut cfg = EnvConfig::new(task);
        cfg.scenario = match (scenario, scenario_text) {
            (Some(_), Some(_)) => {
                return Err(TaskError::new_err(
                    "give either scenario (a path) or scenario_text, not both",
                ));
            }
            (Some(p), None) => ScenarioSource::File(p),
            (None, Some(t)) => ScenarioSource::Text(t),
            (None, None) => ScenarioSource::Default,
        };
        cfg.params = match params_json {
            Some(s) => serde_json::from_str(s).map_err(|e| {
                TaskError::new_err(format!("task parameters are not valid JSON: {e}"))
            })?,
            None => serde_json::Value::Object(Default::default()),
        };
        cfg.num_envs = num_envs;
        cfg.seed = seed;
        cfg.num_threads = num_threads;
        cfg.max_cycles = max_cycles;
        cfg.action = action.parse::<ActionKind>().map_err(to_py)?;
        cfg.autoreset = autoreset_mode.parse::<AutoresetMode>().map_err(to_py)?;
        cfg.global_state = global_state;
        cfg.backend = backend
            .map(|b| b.parse::<colcos_sim::field::BackendChoice>())
            .transpose()
            .map_err(|e| TaskError::new_err(format!("backend: {e}")))?;
        cfg.patch = patch_pixels.map(|pixels| PatchConfig {
            pixels,
            side: patch_side,
        });
        let env = py.detach(|| VecEnv::new(&cfg)).map_err(to_py)?;
        let (e, n) = (env.spec().num_envs, env.spec().num_agents);
        Ok(PyVecEnv {
            inner: Mutex::new(Inner {
                env,
                actions_f: vec![0.0; e * n * 2],
                actions_i: vec![0; e * n],
            }),
        })
    }

    /// Sizes, names and spaces, as a dict.
    fn spec<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let inner = self.lock();
        let s = inner.env.spec();
        let d = PyDict::new(py);
        d.set_item("task", &s.task)?;
        d.set_item("env_name", &s.env_name)?;
        d.set_item("num_envs", s.num_envs)?;
        d.set_item("num_agents", s.num_agents)?;
        d.set_item("num_robots", s.num_robots)?;
        d.set_item("agent_names", s.agent_names.clone())?;
        d.set_item("agent_robots", s.agent_robots.clone())?;
        d.set_item("observation", space_dict(py, &s.observation)?)?;
        d.set_item("action", space_dict(py, &s.action)?)?;
        d.set_item(
            "state",
            s.state.as_ref().map(|x| space_dict(py, x)).transpose()?,
        )?;
        d.set_item(
            "patch",
            s.patch.as_ref().map(|x| space_dict(py, x)).transpose()?,
        )?;
        d.set_item("max_cycles", s.max_cycles)?;
        d.set_item("dt", s.dt)?;
        d.set_item(
            "autoreset_mode",
            format!("{:?}", inner.env.autoreset_mode()),
        )?;
        Ok(d)
    }

    /// Numpy views of the output buffers (no copies; overwritten in place by every step and reset):
    /// `obs [E,N,D] float32`, `rewards [E,N] float32`, `terminated`/`truncated [E,N] bool`,
    /// `state [E,S] float32` (if enabled), `patch [E,N,P,P,3] uint8` (if enabled),
    /// `final_obs [E,N,D]`, `final_mask [E] bool`.
    fn views<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyDict>> {
        let py = slf.py();
        let owner = slf.clone().into_any();
        let (ptrs, spec) = {
            let me = slf.borrow();
            let mut inner = me.lock();
            (inner.env.buffer_ptrs(), inner.env.spec().clone())
        };
        let (e, n) = (spec.num_envs, spec.num_agents);
        let d_obs = spec.observation.flat_len();
        let d = PyDict::new(py);
        // SAFETY: the buffers are allocated once in VecEnv::new and never reallocated; each view keeps
        // `owner` (and so the VecEnv) alive.
        unsafe {
            d.set_item("obs", view(&owner, ptrs.obs, vec![e, n, d_obs])?)?;
            d.set_item("rewards", view(&owner, ptrs.rewards, vec![e, n])?)?;
            d.set_item("terminated", view(&owner, ptrs.terminated, vec![e, n])?)?;
            d.set_item("truncated", view(&owner, ptrs.truncated, vec![e, n])?)?;
            d.set_item(
                "final_obs",
                view(&owner, ptrs.final_obs, vec![e, n, d_obs])?,
            )?;
            d.set_item("final_mask", view(&owner, ptrs.final_mask, vec![e])?)?;
            if let Some(s) = &spec.state {
                d.set_item("state", view(&owner, ptrs.state, vec![e, s.flat_len()])?)?;
            }
            if let Some(Space::Box { shape, .. }) = &spec.patch {
                d.set_item(
                    "patch",
                    view(&owner, ptrs.patch, vec![e, n, shape[0], shape[1], shape[2]])?,
                )?;
            }
        }
        Ok(d)
    }

    /// Resets the worlds where `mask` is true (all if None); a seed restarts the episode count.
    #[pyo3(signature = (seed=None, mask=None))]
    fn reset(
        &self,
        py: Python<'_>,
        seed: Option<u64>,
        mask: Option<PyReadonlyArrayDyn<'_, bool>>,
    ) -> PyResult<()> {
        let mask: Option<Vec<bool>> = match mask {
            Some(m) => {
                if m.ndim() != 1 {
                    return Err(ActionError::new_err(format!(
                        "reset mask must be 1-D of length num_envs, got shape {:?}",
                        m.shape()
                    )));
                }
                Some(m.as_array().iter().copied().collect())
            }
            None => None,
        };
        py.detach(|| self.lock().env.reset(seed, mask.as_deref()))
            .map_err(to_py)
    }

    /// Steps every world. `actions`: float32 `[E, N, 2]` (continuous) or int64 `[E, N]` (discrete),
    /// C-contiguous or not.
    fn step(&self, py: Python<'_>, actions: &Bound<'_, PyAny>) -> PyResult<()> {
        let mut guard = self.lock();
        let inner = &mut *guard;
        let s = inner.env.spec();
        let (e, n) = (s.num_envs, s.num_agents);
        let discrete = matches!(s.action, Space::Discrete { .. });
        if discrete {
            let a: PyReadonlyArrayDyn<'_, i64> = actions.extract().map_err(|_| {
                ActionError::new_err(
                    "discrete actions must be an int64 numpy array of shape (num_envs, num_agents)",
                )
            })?;
            if a.shape() != [e, n] {
                return Err(ActionError::new_err(format!(
                    "actions have shape {:?}, expected ({e}, {n}) = (num_envs, num_agents)",
                    a.shape()
                )));
            }
            inner
                .actions_i
                .iter_mut()
                .zip(a.as_array().iter())
                .for_each(|(d, s)| *d = *s);
            let (env, acts) = (&mut inner.env, &inner.actions_i);
            py.detach(|| env.step(Actions::Discrete(acts)))
                .map_err(to_py)
        } else {
            let a: PyReadonlyArrayDyn<'_, f32> = actions
                .extract()
                .map_err(|_| ActionError::new_err("continuous actions must be a float32 numpy array of shape (num_envs, num_agents, 2)"))?;
            if a.shape() != [e, n, 2] {
                return Err(ActionError::new_err(format!(
                    "actions have shape {:?}, expected ({e}, {n}, 2) = (num_envs, num_agents, wheels)",
                    a.shape()
                )));
            }
            match a.as_slice() {
                Ok(src) => inner.actions_f.copy_from_slice(src),
                Err(_) => inner
                    .actions_f
                    .iter_mut()
                    .zip(a.as_array().iter())
                    .for_each(|(d, s)| *d = *s),
            }
            let (env, acts) = (&mut inner.env, &inner.actions_f);
            py.detach(|| env.step(Actions::Continuous(acts)))
                .map_err(to_py)
        }
    }

    /// The screen of world `world` with the robots drawn on it, `(H, W, 3)` uint8.
    #[pyo3(signature = (world=0, width=640))]
    fn render<'py>(
        &self,
        py: Python<'py>,
        world: usize,
        width: u32,
    ) -> PyResult<Bound<'py, PyAny>> {
        let img = py
            .detach(|| self.lock().env.render(world, width))
            .map_err(to_py)?;
        let (w, h) = (img.width() as usize, img.height() as usize);
        let flat = PyArray1::from_vec(py, img.into_raw());
        Ok(flat.reshape([h, w, 3])?.into_any())
    }

    /// Steps taken in the current episode of `world`.
    fn episode_steps(&self, world: usize) -> PyResult<u64> {
        self.check_world(world)?;
        Ok(self.lock().env.episode_steps(world))
    }

    /// Episode number of `world` since the seed was last set.
    fn episode(&self, world: usize) -> PyResult<u64> {
        self.check_world(world)?;
        Ok(self.lock().env.episode(world))
    }

    /// True poses `(R, 3)`: x m, y m, heading rad, of every robot of `world` (for analysis, not for
    /// policies).
    fn poses<'py>(&self, py: Python<'py>, world: usize) -> PyResult<Bound<'py, PyAny>> {
        self.check_world(world)?;
        let inner = self.lock();
        let w = inner.env.world(world).expect("checked");
        let flat: Vec<f32> = w
            .poses()
            .iter()
            .flat_map(|p| [p.pos.x, p.pos.y, p.heading])
            .collect();
        let r = w.robot_count();
        Ok(PyArray1::from_vec(py, flat).reshape([r, 3])?.into_any())
    }

    /// Roles of the robots of a world, in robot order.
    fn roles(&self) -> Vec<String> {
        let inner = self.lock();
        let w = inner.env.world(0).expect("num_envs >= 1");
        (0..w.robot_count())
            .map(|i| w.role(i).to_string())
            .collect()
    }

    /// What steps the grid pheromones: `"cpu"` or `"gpu"`.
    #[getter]
    fn backend_name(&self) -> &'static str {
        self.lock().env.backend().name()
    }

    /// One line on the field backend: `gpu: <adapter>` or `cpu (<why>)`.
    #[getter]
    fn backend_info(&self) -> String {
        self.lock().env.backend().describe().to_string()
    }

    /// The scenario actually used, as TOML.
    fn scenario_toml(&self) -> String {
        self.lock().env.scenario().to_toml()
    }

    /// Current base seed.
    #[getter]
    fn seed(&self) -> u64 {
        self.lock().env.seed()
    }
}

impl PyVecEnv {
    fn check_world(&self, world: usize) -> PyResult<()> {
        let e = self.lock().env.spec().num_envs;
        if world >= e {
            return Err(TaskError::new_err(format!(
                "world {world} does not exist (num_envs = {e})"
            )));
        }
        Ok(())
    }
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyVecEnv>()
}
