//! `colcos._core.VecEnv`: the batched environment, its buffers handed to Python as numpy views.
//!
//! Threads: every call waits for the environment's lock with the GIL released (`py.detach`), so
//! that a thread stepping (which holds the lock and has released the GIL) and a thread asking for
//! anything else never wait on each other. Every entry point runs under `args::guard`.
use crate::args::{self, guard};
use crate::errors::{Kind, to_py};
use crate::limits;
use colcos_env::{
    ActionKind, Actions, AutoresetMode, EnvConfig, PatchConfig, ScenarioSource, Space, VecEnv,
};
use numpy::ndarray::{ArrayView, IxDyn};
use numpy::{
    Element, PyArray, PyArray1, PyArrayMethods, PyReadonlyArrayDyn, PyUntypedArrayMethods,
};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::sync::{Mutex, MutexGuard};

/// The environment. Behind a mutex because pyo3 classes must be `Sync` (behaviours and field
/// backends are `Send` only).
pub(crate) struct Inner {
    pub env: VecEnv,
}

#[pyclass(module = "colcos._core", name = "VecEnv", frozen)]
pub struct PyVecEnv {
    inner: Mutex<Inner>,
    /// Fixed at construction, read without the lock.
    num_envs: usize,
    num_agents: usize,
    /// None: discrete actions; Some(w): continuous rows of `w` entries (wheels, deposit rates).
    width: Option<usize>,
}

impl PyVecEnv {
    /// The lock. Call only with the GIL released (inside `py.detach`).
    pub(crate) fn lock(&self) -> MutexGuard<'_, Inner> {
        // A panic while holding the lock is reported as an error; keep going with the data.
        self.inner.lock().unwrap_or_else(|e| e.into_inner())
    }

    fn world_index(&self, world: &Bound<'_, PyAny>) -> PyResult<usize> {
        let last = self.num_envs as u64 - 1;
        args::int_in(world, "world", 0, last).map(|w| w as usize)
    }
}

/// Raw buffer pointers carried out of a `detach` closure.
pub(crate) struct Ptrs<T>(pub T);
// SAFETY: plain addresses of buffers owned by the env, only dereferenced with the GIL held while the
// env is alive (see `views`).
unsafe impl<T> Send for Ptrs<T> {}

/// A numpy view of the elements at `ptr` shaped `shape`, keeping `owner` alive.
///
/// # Safety
/// `ptr..ptr + product(shape)` must stay valid for as long as `owner` lives.
pub(crate) unsafe fn view<'py, T: Element>(
    owner: &Bound<'py, PyAny>,
    ptr: *mut T,
    shape: Vec<usize>,
) -> PyResult<Bound<'py, PyAny>> {
    let a = unsafe { ArrayView::from_shape_ptr(IxDyn(&shape), ptr as *const T) };
    Ok(unsafe { PyArray::borrow_from_array(&a, owner.clone()) }.into_any())
}

/// The configuration from the constructor's arguments, each checked and named.
#[allow(clippy::too_many_arguments)]
pub(crate) fn config(
    task: &Bound<'_, PyAny>,
    num_envs: Option<&Bound<'_, PyAny>>,
    seed: Option<&Bound<'_, PyAny>>,
    num_threads: Option<&Bound<'_, PyAny>>,
    scenario: Option<&Bound<'_, PyAny>>,
    scenario_text: Option<&Bound<'_, PyAny>>,
    max_cycles: Option<&Bound<'_, PyAny>>,
    action: Option<&Bound<'_, PyAny>>,
    autoreset_mode: Option<&Bound<'_, PyAny>>,
    global_state: Option<&Bound<'_, PyAny>>,
    patch_pixels: Option<&Bound<'_, PyAny>>,
    patch_side: Option<&Bound<'_, PyAny>>,
    params_json: Option<&Bound<'_, PyAny>>,
    backend: Option<&Bound<'_, PyAny>>,
    physics: Option<&Bound<'_, PyAny>>,
) -> PyResult<EnvConfig> {
    fn some<'a, 'py>(v: Option<&'a Bound<'py, PyAny>>) -> Option<&'a Bound<'py, PyAny>> {
        v.filter(|v| !v.is_none())
    }
    let mut cfg = EnvConfig::new(args::text(task, "task")?);
    let scenario_path = match some(scenario) {
        Some(p) => Some(p.extract::<std::path::PathBuf>().map_err(|_| {
            Kind::ArgumentType.err(format!(
                "scenario must be a path (str or os.PathLike), got {}",
                args::show(p)
            ))
        })?),
        None => None,
    };
    cfg.scenario = match (
        scenario_path,
        args::opt_text(scenario_text, "scenario_text")?,
    ) {
        (Some(_), Some(_)) => {
            return Err(Kind::Task.err("give either scenario (a path) or scenario_text, not both"));
        }
        (Some(p), None) => ScenarioSource::File(p),
        (None, Some(t)) => ScenarioSource::Text(t),
        (None, None) => ScenarioSource::Default,
    };
    if let Some(s) = args::opt_text(params_json, "params_json")? {
        let v: serde_json::Value = serde_json::from_str(&s).map_err(|e| {
            Kind::Task.err(format!(
                "task parameters (params_json) are not valid JSON: {e}"
            ))
        })?;
        limits::check_params("", &v).map_err(|e| Kind::Task.err(e))?;
        cfg.params = v;
    }
    if let Some(n) = some(num_envs) {
        cfg.num_envs = args::int_in(n, "num_envs", 1, limits::MAX_NUM_ENVS)? as usize;
    }
    if let Some(s) = some(seed) {
        cfg.seed = args::seed(s, "seed")?;
    }
    if let Some(t) = some(num_threads) {
        cfg.num_threads = Some(args::int_in(t, "num_threads", 1, limits::MAX_THREADS)? as usize);
    }
    if let Some(m) = some(max_cycles) {
        // 0: the scenario's duration.
        cfg.max_cycles = args::int_in(m, "max_cycles", 0, limits::MAX_CYCLES)?;
    }
    if let Some(a) = args::opt_text(action, "action")? {
        cfg.action = a.parse::<ActionKind>().map_err(to_py)?;
    }
    if let Some(a) = args::opt_text(autoreset_mode, "autoreset_mode")? {
        cfg.autoreset = a.parse::<AutoresetMode>().map_err(to_py)?;
    }
    if let Some(g) = some(global_state) {
        cfg.global_state = args::flag(g, "global_state")?;
    }
    if let Some(p) = some(patch_pixels) {
        let pixels = args::int_in(p, "patch_pixels", 1, limits::MAX_PATCH_PIXELS)? as usize;
        let side = match some(patch_side) {
            Some(s) => args::real(s, "patch_side")? as f32,
            None => PatchConfig::default().side,
        };
        cfg.patch = Some(PatchConfig { pixels, side });
    }
    cfg.backend = args::opt_text(backend, "backend")?
        .map(|b| b.parse::<colcos_sim::field::BackendChoice>())
        .transpose()
        .map_err(|e| Kind::Task.err(format!("backend: {e}")))?;
    cfg.physics = match args::opt_text(physics, "physics")?.as_deref() {
        None => None,
        Some("rapier") => Some(colcos_sim::robot::PhysicsBackend::Rapier),
        Some("discs") => Some(colcos_sim::robot::PhysicsBackend::Discs),
        Some(other) => {
            return Err(Kind::Task.err(format!(
                "physics = {other:?}: \"rapier\" or \"discs\" (or None: the scenario's)"
            )));
        }
    };
    Ok(cfg)
}

#[pymethods]
impl PyVecEnv {
    #[new]
    #[pyo3(signature = (task, num_envs=None, seed=None, num_threads=None, scenario=None, scenario_text=None, max_cycles=None, action=None, autoreset_mode=None, global_state=None, patch_pixels=None, patch_side=None, params_json=None, backend=None, physics=None))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        task: &Bound<'_, PyAny>,
        num_envs: Option<&Bound<'_, PyAny>>,
        seed: Option<&Bound<'_, PyAny>>,
        num_threads: Option<&Bound<'_, PyAny>>,
        scenario: Option<&Bound<'_, PyAny>>,
        scenario_text: Option<&Bound<'_, PyAny>>,
        max_cycles: Option<&Bound<'_, PyAny>>,
        action: Option<&Bound<'_, PyAny>>,
        autoreset_mode: Option<&Bound<'_, PyAny>>,
        global_state: Option<&Bound<'_, PyAny>>,
        patch_pixels: Option<&Bound<'_, PyAny>>,
        patch_side: Option<&Bound<'_, PyAny>>,
        params_json: Option<&Bound<'_, PyAny>>,
        backend: Option<&Bound<'_, PyAny>>,
        physics: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        guard(|| {
            let cfg = config(
                task,
                num_envs,
                seed,
                num_threads,
                scenario,
                scenario_text,
                max_cycles,
                action,
                autoreset_mode,
                global_state,
                patch_pixels,
                patch_side,
                params_json,
                backend,
                physics,
            )?;
            let env = py
                .detach(|| {
                    limits::check_batch_memory(&cfg)?;
                    VecEnv::new(&cfg)
                })
                .map_err(to_py)?;
            let s = env.spec();
            let (num_envs, num_agents) = (s.num_envs, s.num_agents);
            let width = action_width(&s.action);
            Ok(PyVecEnv {
                inner: Mutex::new(Inner { env }),
                num_envs,
                num_agents,
                width,
            })
        })
    }

    /// Sizes, names and spaces, as a dict.
    fn spec<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        guard(|| {
            let (spec, mode) = py.detach(|| {
                let g = self.lock();
                (
                    g.env.spec().clone(),
                    format!("{:?}", g.env.autoreset_mode()),
                )
            });
            crate::spec::spec_dict(py, &spec, &mode)
        })
    }

    /// Numpy views of the output buffers (no copies; overwritten in place by every step and reset):
    /// `obs [E,N,D] float32`, `rewards [E,N] float32`, `terminated`/`truncated [E,N] bool`,
    /// `state [E,S] float32` (if enabled), `patch [E,N,P,P,3] uint8` (if enabled),
    /// `final_obs [E,N,D]`, `final_mask [E] bool`.
    fn views<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyDict>> {
        guard(|| {
            let py = slf.py();
            let owner = slf.clone().into_any();
            let me: &PyVecEnv = slf.get();
            let (ptrs, spec) = py.detach(|| {
                let mut g = me.lock();
                (Ptrs(g.env.buffer_ptrs()), g.env.spec().clone())
            });
            let d = PyDict::new(py);
            // SAFETY: the buffers are allocated once in VecEnv::new and never reallocated; each view
            // keeps `owner` (and so the VecEnv) alive.
            unsafe { output_views(&d, &owner, &ptrs.0, &spec)? };
            Ok(d)
        })
    }

    /// Resets the worlds where `mask` (bool array of length num_envs) is true, all if None; a seed
    /// (an integer in 0..=2**64-1) becomes the base seed and restarts the episode count.
    #[pyo3(signature = (seed=None, mask=None))]
    fn reset(
        &self,
        py: Python<'_>,
        seed: Option<&Bound<'_, PyAny>>,
        mask: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<()> {
        guard(|| {
            let seed = match seed.filter(|s| !s.is_none()) {
                Some(s) => Some(args::seed(s, "seed")?),
                None => None,
            };
            let mask = match mask.filter(|m| !m.is_none()) {
                Some(m) => Some(self.mask(m)?),
                None => None,
            };
            py.detach(|| self.lock().env.reset(seed, mask.as_deref()))
                .map_err(to_py)
        })
    }

    /// Steps every world. `actions`: float32 `[E, N, 2 + D]` (continuous: wheels, then a rate per
    /// deposit action) or int64 `[E, N]` (discrete), C-contiguous or not.
    fn step(&self, py: Python<'_>, actions: &Bound<'_, PyAny>) -> PyResult<()> {
        guard(|| {
            let (e, n) = (self.num_envs, self.num_agents);
            let acts = owned_actions(actions, e, n, self.width)?;
            py.detach(|| {
                let mut g = self.lock();
                match &acts {
                    Owned::Discrete(a) => g.env.step(Actions::Discrete(a)),
                    Owned::Continuous(a) => g.env.step(Actions::Continuous(a)),
                }
            })
            .map_err(to_py)
        })
    }

    /// The screen of world `world` with the robots drawn on it, `(H, W, 3)` uint8, `width` pixels
    /// wide (16..=7680; the height follows the screen's aspect).
    #[pyo3(signature = (world=None, width=None))]
    fn render<'py>(
        &self,
        py: Python<'py>,
        world: Option<&Bound<'py, PyAny>>,
        width: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        guard(|| {
            let w = match world.filter(|w| !w.is_none()) {
                Some(w) => self.world_index(w)?,
                None => 0,
            };
            let width = match width.filter(|w| !w.is_none()) {
                Some(x) => args::int_in(x, "width", 16, limits::MAX_RENDER_WIDTH)? as u32,
                None => 640,
            };
            let img = py.detach(|| {
                let g = self.lock();
                let size = g.env.scenario().spec.screen.size;
                let height = (width as f64 * size[1] as f64 / size[0] as f64).round();
                let pixels = height * width as f64;
                if pixels.is_nan() || pixels > limits::MAX_RENDER_PIXELS as f64 {
                    return Err(Err(format!(
                        "width = {width}: the image would be {width} x {height} pixels (the screen is \
                         {} x {} m), more than {} pixels; use a smaller width",
                        size[0],
                        size[1],
                        limits::MAX_RENDER_PIXELS
                    )));
                }
                g.env.render(w, width).map_err(Ok)
            })
            .map_err(|e| match e {
                Ok(env_err) => to_py(env_err),
                Err(msg) => Kind::Task.err(msg),
            })?;
            let (w, h) = (img.width() as usize, img.height() as usize);
            let flat = PyArray1::from_vec(py, img.into_raw());
            Ok(flat.reshape([h, w, 3])?.into_any())
        })
    }

    /// Steps taken in the current episode of `world`.
    fn episode_steps(&self, py: Python<'_>, world: &Bound<'_, PyAny>) -> PyResult<u64> {
        guard(|| {
            let w = self.world_index(world)?;
            Ok(py.detach(|| self.lock().env.episode_steps(w)))
        })
    }

    /// Episode number of `world` since the seed was last set.
    fn episode(&self, py: Python<'_>, world: &Bound<'_, PyAny>) -> PyResult<u64> {
        guard(|| {
            let w = self.world_index(world)?;
            Ok(py.detach(|| self.lock().env.episode(w)))
        })
    }

    /// True poses `(R, 3)`: x m, y m, heading rad, of every robot of `world` (for analysis, not for
    /// policies).
    fn poses<'py>(
        &self,
        py: Python<'py>,
        world: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        guard(|| {
            let w = self.world_index(world)?;
            let (flat, r) = py.detach(|| {
                let g = self.lock();
                let world = g.env.world(w);
                let flat: Vec<f32> = world
                    .iter()
                    .flat_map(|w| w.poses())
                    .flat_map(|p| [p.pos.x, p.pos.y, p.heading])
                    .collect();
                (flat, world.map_or(0, |w| w.robot_count()))
            });
            Ok(PyArray1::from_vec(py, flat).reshape([r, 3])?.into_any())
        })
    }

    /// Roles of the robots of a world, in robot order.
    fn roles(&self, py: Python<'_>) -> PyResult<Vec<String>> {
        guard(|| {
            Ok(py.detach(|| {
                let g = self.lock();
                g.env.world(0).map_or_else(Vec::new, |w| {
                    (0..w.robot_count())
                        .map(|i| w.role(i).to_string())
                        .collect()
                })
            }))
        })
    }

    /// What steps the grid pheromones: `"cpu"` or `"gpu"`.
    #[getter]
    fn backend_name(&self, py: Python<'_>) -> PyResult<&'static str> {
        guard(|| Ok(py.detach(|| self.lock().env.backend().name())))
    }

    /// One line on the field backend: `gpu: <adapter>` or `cpu (<why>)`.
    #[getter]
    fn backend_info(&self, py: Python<'_>) -> PyResult<String> {
        guard(|| Ok(py.detach(|| self.lock().env.backend().describe().to_string())))
    }

    /// The scenario actually used, as TOML.
    fn scenario_toml(&self, py: Python<'_>) -> PyResult<String> {
        guard(|| Ok(py.detach(|| self.lock().env.scenario().to_toml())))
    }

    /// Current base seed.
    #[getter]
    fn seed(&self, py: Python<'_>) -> PyResult<u64> {
        guard(|| Ok(py.detach(|| self.lock().env.seed())))
    }
}

/// Puts numpy views of the output buffers at `bufs` into `d`: `obs [E,N,D]`, `rewards`,
/// `terminated`, `truncated`, `shield [E,N]`, `final_obs [E,N,D]`, `final_mask [E]`, and `state [E,S]`
/// and `patch [E,N,P,P,3]` where `spec` has them.
///
/// # Safety
/// The buffers must be those of an `Outputs` made for `spec` and stay valid for as long as `owner`
/// lives.
pub(crate) unsafe fn output_views<'py>(
    d: &Bound<'py, PyDict>,
    owner: &Bound<'py, PyAny>,
    bufs: &colcos_env::BufferPtrs,
    spec: &colcos_env::EnvSpec,
) -> PyResult<()> {
    let (e, n) = (spec.num_envs, spec.num_agents);
    let obs = vec![e, n, spec.observation.flat_len()];
    unsafe {
        d.set_item("obs", view(owner, bufs.obs, obs.clone())?)?;
        d.set_item("rewards", view(owner, bufs.rewards, vec![e, n])?)?;
        d.set_item("terminated", view(owner, bufs.terminated, vec![e, n])?)?;
        d.set_item("truncated", view(owner, bufs.truncated, vec![e, n])?)?;
        d.set_item("shield", view(owner, bufs.shield, vec![e, n])?)?;
        d.set_item("final_obs", view(owner, bufs.final_obs, obs)?)?;
        d.set_item("final_mask", view(owner, bufs.final_mask, vec![e])?)?;
        if let Some(s) = &spec.state {
            d.set_item("state", view(owner, bufs.state, vec![e, s.flat_len()])?)?;
        }
        if let Some(Space::Box { shape, .. }) = &spec.patch {
            let patch = vec![e, n, shape[0], shape[1], shape[2]];
            d.set_item("patch", view(owner, bufs.patch, patch)?)?;
        }
    }
    Ok(())
}

/// Actions copied out of numpy (before the env's lock is taken, with the GIL held).
pub(crate) enum Owned {
    Continuous(Vec<f32>),
    Discrete(Vec<i64>),
}

/// `actions` checked and copied: int64 `[e, n]` (discrete) or float32 `[e, n, 2]`, C-contiguous or
/// not.
/// The width of a continuous action row, or None for discrete actions.
pub(crate) fn action_width(space: &Space) -> Option<usize> {
    match space {
        Space::Box { shape, .. } => Some(shape.iter().product()),
        Space::Discrete { .. } => None,
    }
}

pub(crate) fn owned_actions(
    actions: &Bound<'_, PyAny>,
    e: usize,
    n: usize,
    width: Option<usize>,
) -> PyResult<Owned> {
    let Some(w) = width else {
        let a: PyReadonlyArrayDyn<'_, i64> = actions.extract().map_err(|_| {
            Kind::ActionType.err(format!(
                "discrete actions must be an int64 numpy array of shape ({e}, {n}) = \
                 (num_envs, num_agents), got {}",
                args::show(actions)
            ))
        })?;
        if a.shape() != [e, n] {
            return Err(Kind::Action.err(format!(
                "actions have shape {:?}, expected ({e}, {n}) = (num_envs, num_agents)",
                a.shape()
            )));
        }
        return Ok(Owned::Discrete(a.as_array().iter().copied().collect()));
    };
    let row = if w == 2 {
        "wheels".to_string()
    } else {
        format!("2 wheels + {} deposit rates", w - 2)
    };
    let a: PyReadonlyArrayDyn<'_, f32> = actions.extract().map_err(|_| {
        Kind::ActionType.err(format!(
            "continuous actions must be a float32 numpy array of shape ({e}, {n}, {w}) = \
             (num_envs, num_agents, {row}), got {}",
            args::show(actions)
        ))
    })?;
    if a.shape() != [e, n, w] {
        return Err(Kind::Action.err(format!(
            "actions have shape {:?}, expected ({e}, {n}, {w}) = (num_envs, num_agents, {row})",
            a.shape()
        )));
    }
    Ok(Owned::Continuous(match a.as_slice() {
        Ok(src) => src.to_vec(),
        Err(_) => a.as_array().iter().copied().collect(),
    }))
}

impl PyVecEnv {
    /// A reset mask: a 1-D bool array (or sequence of bools) of length num_envs.
    fn mask(&self, m: &Bound<'_, PyAny>) -> PyResult<Vec<bool>> {
        let e = self.num_envs;
        let a: PyReadonlyArrayDyn<'_, bool> = m.extract().map_err(|_| {
            Kind::ArgumentType.err(format!(
                "reset mask must be a bool numpy array of shape ({e},), got {}",
                args::show(m)
            ))
        })?;
        if a.shape() != [e] {
            return Err(Kind::Task.err(format!(
                "reset mask must have shape ({e},) = (num_envs,), got shape {:?}",
                a.shape()
            )));
        }
        Ok(a.as_array().iter().copied().collect())
    }
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    limits::register(m)?;
    m.add_class::<PyVecEnv>()
}
