//! `colcos._core.VecEnv`: the batched environment, its buffers handed to Python as numpy views.
//!
//! Threads: every call waits for the environment's lock with the GIL released (`py.detach`), so
//! that a thread stepping (which holds the lock and has released the GIL) and a thread asking for
//! anything else never wait on each other. Every entry point runs under `args::guard`.
use crate::arena_io::{self, action_width};
use crate::args::{self, Keywords, guard};
use crate::errors::{Kind, to_py};
use crate::limits;
use colcos_env::{
    ActionKind, Actions, AutoresetMode, BufferPtrs, EnvConfig, EnvSpec, PatchConfig,
    ScenarioSource, VecEnv,
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

/// The configuration from a constructor's task and keyword arguments, each checked and named, of
/// one world (`batch` false: a plant's) or of a batch (also `num_envs`, `num_threads` and
/// `autoreset_mode`). Takes the arguments it knows out of `kw`.
pub(crate) fn config(
    task: &Bound<'_, PyAny>,
    kw: &Keywords<'_>,
    batch: bool,
) -> PyResult<EnvConfig> {
    let mut cfg = EnvConfig::new(args::text(task, "task")?);
    let scenario_path = kw
        .take("scenario")?
        .map(|p| args::path(&p, "scenario"))
        .transpose()?;
    cfg.scenario = match (scenario_path, kw.text("scenario_text")?) {
        (Some(_), Some(_)) => {
            return Err(Kind::Task.err("give either scenario (a path) or scenario_text, not both"));
        }
        (Some(p), None) => ScenarioSource::File(p),
        (None, Some(t)) => ScenarioSource::Text(t),
        (None, None) => ScenarioSource::Default,
    };
    if let Some(s) = kw.text("params_json")? {
        let v: serde_json::Value = serde_json::from_str(&s).map_err(|e| {
            Kind::Task.err(format!(
                "task parameters (params_json) are not valid JSON: {e}"
            ))
        })?;
        limits::check_params("", &v).map_err(|e| Kind::Task.err(e))?;
        cfg.params = v;
    }
    if batch {
        if let Some(n) = kw.take("num_envs")? {
            cfg.num_envs = args::int_in(&n, "num_envs", 1, limits::MAX_NUM_ENVS)? as usize;
        }
        if let Some(t) = kw.take("num_threads")? {
            let threads = args::int_in(&t, "num_threads", 1, limits::MAX_THREADS)?;
            cfg.num_threads = Some(threads as usize);
        }
        if let Some(a) = kw.text("autoreset_mode")? {
            cfg.autoreset = a.parse::<AutoresetMode>().map_err(to_py)?;
        }
    } else {
        cfg.num_threads = Some(1);
    }
    if let Some(s) = arena_io::opt_seed(kw.take("seed")?.as_ref())? {
        cfg.seed = s;
    }
    if let Some(m) = kw.take("max_cycles")? {
        // 0: the scenario's duration.
        cfg.max_cycles = args::int_in(&m, "max_cycles", 0, limits::MAX_CYCLES)?;
    }
    if let Some(a) = kw.text("action")? {
        cfg.action = a.parse::<ActionKind>().map_err(to_py)?;
    }
    if let Some(g) = kw.take("global_state")? {
        cfg.global_state = args::flag(&g, "global_state")?;
    }
    let side = kw.take("patch_side")?;
    if let Some(p) = kw.take("patch_pixels")? {
        let pixels = args::int_in(&p, "patch_pixels", 1, limits::MAX_PATCH_PIXELS)? as usize;
        let side = match side {
            Some(s) => args::real(&s, "patch_side")? as f32,
            None => PatchConfig::default().side,
        };
        cfg.patch = Some(PatchConfig { pixels, side });
    }
    cfg.backend = kw
        .text("backend")?
        .map(|b| b.parse::<colcos_sim::field::BackendChoice>())
        .transpose()
        .map_err(|e| Kind::Task.err(format!("backend: {e}")))?;
    cfg.physics = match kw.text("physics")?.as_deref() {
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
    /// `task` and the keyword arguments `num_envs`, `seed`, `num_threads`, `scenario` (a path) or
    /// `scenario_text`, `max_cycles`, `action`, `autoreset_mode`, `global_state`, `patch_pixels`,
    /// `patch_side`, `params_json`, `backend`, `physics` (None: the default).
    #[new]
    #[pyo3(signature = (task, **options))]
    fn new(
        py: Python<'_>,
        task: &Bound<'_, PyAny>,
        options: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Self> {
        guard(|| {
            let kw = Keywords::new(py, options, "VecEnv")?;
            let cfg = config(task, &kw, true)?;
            kw.finish()?;
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
        guard(|| arena_io::views(slf))
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
        guard(|| arena_io::reset(self, py, seed, mask))
    }

    /// Steps every world. `actions`: float32 `[E, N, 2 + D]` (continuous: wheels, then a rate per
    /// deposit action) or int64 `[E, N]` (discrete), C-contiguous or not.
    fn step(&self, py: Python<'_>, actions: &Bound<'_, PyAny>) -> PyResult<()> {
        guard(|| arena_io::step(self, py, actions, false))
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
            let w = args::given(world).map_or(Ok(0), |w| self.world_index(w))?;
            let width = arena_io::render_width(width, limits::MAX_RENDER_WIDTH)?;
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
            arena_io::image(py, img)
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
            let poses = py.detach(|| {
                let g = self.lock();
                g.env.world(w).map_or_else(Vec::new, |w| w.poses().to_vec())
            });
            arena_io::pose_rows(py, poses)
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

// SAFETY: the buffers are allocated once in VecEnv::new and never reallocated.
unsafe impl arena_io::Arena for PyVecEnv {
    type Error = colcos_env::EnvError;
    fn py_err(e: Self::Error) -> PyErr {
        to_py(e)
    }
    fn sizes(&self) -> (usize, usize, Option<usize>) {
        (self.num_envs, self.num_agents, self.width)
    }
    fn buffers(&self) -> (BufferPtrs, EnvSpec) {
        let mut g = self.lock();
        (g.env.buffer_ptrs(), g.env.spec().clone())
    }
    fn reset_now(&self, seed: Option<u64>, mask: Option<&[bool]>) -> Result<(), Self::Error> {
        self.lock().env.reset(seed, mask)
    }
    fn step_now(&self, actions: Actions<'_>, deferred: bool) -> Result<(), Self::Error> {
        let env = &mut self.lock().env;
        if deferred {
            env.step_deferred(actions)
        } else {
            env.step(actions)
        }
    }
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    limits::register(m)?;
    m.add_class::<PyVecEnv>()
}
