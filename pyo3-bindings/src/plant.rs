//! `colcos._core.Plant`: one arena of a task on the digital twin, the lab's rig or a recorded rig run,
//! with the buffers, spec and methods of a one-world `VecEnv`, so that the PettingZoo faces run on it
//! unchanged. The GIL is released around every call that waits on the arena (reset, step).
use crate::arena_io::{self, action_width};
use crate::args::{self, Keywords, guard};
use crate::errors::{Kind, to_py};
use colcos_env::{Actions, BufferPtrs, EnvSpec};
use colcos_plant::{LiveEnv, PlantError, PlantKind, PlantOptions, TwinScenario};
use colcos_sim::scenario::Scenario;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::sync::{Mutex, MutexGuard};

#[pyclass(module = "colcos._core", name = "Plant", frozen)]
pub struct PyPlant {
    inner: Mutex<LiveEnv>,
    num_agents: usize,
    width: Option<usize>,
}

pub(crate) fn plant_err(e: PlantError) -> PyErr {
    let msg = e.to_string();
    match e {
        PlantError::Env(e) => to_py(e),
        PlantError::Sim(_) => Kind::Scenario.err(msg),
        PlantError::Option { .. } => Kind::Task.err(msg),
        PlantError::Source(_) | PlantError::Link(_) | PlantError::Unreachable(_) => {
            Kind::Unreachable.err(msg)
        }
        PlantError::Io(_) => Kind::State.err(msg),
        PlantError::Replay(_) | PlantError::State(_) => Kind::State.err(msg),
    }
}

/// The twin's own scenario from at most one of a file, TOML text and JSON overrides.
fn twin_choice(
    file: Option<String>,
    text: Option<String>,
    overrides: Option<String>,
) -> PyResult<Option<TwinScenario>> {
    let scenario_err =
        |e: colcos_sim::error::SimError| Kind::Scenario.err(format!("twin_scenario: {e}"));
    Ok(match (file, text, overrides) {
        (None, None, None) => None,
        (Some(f), None, None) => Some(TwinScenario::Full(Box::new(
            Scenario::from_file(std::path::Path::new(&f)).map_err(scenario_err)?,
        ))),
        (None, Some(t), None) => Some(TwinScenario::Full(Box::new(
            Scenario::from_toml_str(&t, ".").map_err(scenario_err)?,
        ))),
        (None, None, Some(j)) => {
            let map: serde_json::Map<String, serde_json::Value> = serde_json::from_str(&j)
                .map_err(|e| {
                    Kind::Task.err(format!(
                        "twin_scenario: overrides must be a JSON object: {e}"
                    ))
                })?;
            Some(TwinScenario::Overrides(map.into_iter().collect()))
        }
        _ => {
            return Err(Kind::Task
                .err("twin_scenario: give one of a scenario file, scenario text or overrides"));
        }
    })
}

impl PyPlant {
    /// The lock. Call only with the GIL released (inside `py.detach`).
    pub(crate) fn lock(&self) -> MutexGuard<'_, LiveEnv> {
        self.inner.lock().unwrap_or_else(|e| e.into_inner())
    }
}

#[pymethods]
impl PyPlant {
    /// `plant`: "twin", "rig" or "replay"; keyword arguments `tracker`/`robots`: the URLs (a twin
    /// without them starts in this process on loopback); `log`: the rig log to replay, or to write
    /// (twin, rig); `goto`: reset drives the robots to the episode's start poses, for at most
    /// `goto_timeout` s. `twin_scenario` (a file) / `twin_scenario_text` (TOML) /
    /// `twin_overrides_json` (a JSON object of key paths and values over the host's scenario): what
    /// a twin started here plays instead; `truth` (a file of `[[robot]]` entries, `colcos twin
    /// --truth`): its robots' hidden values. The others are `VecEnv`'s (one world).
    #[new]
    #[pyo3(signature = (plant, task, **options))]
    fn new(
        py: Python<'_>,
        plant: &Bound<'_, PyAny>,
        task: &Bound<'_, PyAny>,
        options: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Self> {
        guard(|| {
            let kw = Keywords::new(py, options, "Plant")?;
            let kind: PlantKind = args::text(plant, "plant")?.parse().map_err(plant_err)?;
            let mut opts = PlantOptions::new(kind);
            opts.tracker = kw.text("tracker")?;
            opts.robots = kw.text("robots")?;
            opts.log = kw.take("log")?.map(|l| args::path(&l, "log")).transpose()?;
            if let Some(g) = kw.take("goto")? {
                opts.goto = args::flag(&g, "goto")?;
            }
            let timeout = match kw.take("goto_timeout")? {
                Some(t) => args::real(&t, "goto_timeout")?,
                None => opts.goto_timeout,
            };
            if !(0.0..=600.0).contains(&timeout) {
                return Err(
                    Kind::Task.err(format!("goto_timeout = {timeout}: must be in 0..=600 s"))
                );
            }
            opts.goto_timeout = timeout;
            opts.twin_scenario = twin_choice(
                kw.text("twin_scenario")?,
                kw.text("twin_scenario_text")?,
                kw.text("twin_overrides_json")?,
            )?;
            opts.twin_truth = kw.text("truth")?.map(std::path::PathBuf::from);
            let cfg = crate::vec_env::config(task, &kw, false)?;
            kw.finish()?;
            let env = py.detach(|| LiveEnv::new(&cfg, &opts)).map_err(plant_err)?;
            let s = env.spec();
            let (num_agents, width) = (s.num_agents, action_width(&s.action));
            Ok(PyPlant {
                inner: Mutex::new(env),
                num_agents,
                width,
            })
        })
    }

    /// Sizes, names and spaces, as a dict (those of the simulated environment).
    fn spec<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        guard(|| {
            let spec = py.detach(|| self.lock().spec().clone());
            crate::spec::spec_dict(py, &spec, "Disabled")
        })
    }

    /// Numpy views of the output buffers, overwritten by every reset and step: `obs [1,N,D]`,
    /// `rewards [1,N]`, `terminated`/`truncated [1,N]`, `shield [1,N]` (bit 0 capped, bit 1 walled),
    /// `final_obs [1,N,D]` and `final_mask [1]` (never set: a plant does not reset itself),
    /// `state [1,S]` and `patch [1,N,P,P,3]` if enabled.
    fn views<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyDict>> {
        guard(|| arena_io::views(slf))
    }

    /// A new episode (on the twin and the rig: the robots driven to its start poses first); a seed
    /// becomes the scenario's seed.
    #[pyo3(signature = (seed=None, mask=None))]
    fn reset(
        &self,
        py: Python<'_>,
        seed: Option<&Bound<'_, PyAny>>,
        mask: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<()> {
        guard(|| {
            // Refused before the seed is read, as the one-world rule comes first.
            if args::given(mask).is_some() {
                return Err(Kind::Task.err("a plant has one world: reset takes no mask"));
            }
            arena_io::reset(self, py, seed, None)
        })
    }

    /// One step (paced to the screen's rate on the twin and the rig): float32 `[1, N, 2 + D]` or
    /// int64 `[1, N]`.
    fn step(&self, py: Python<'_>, actions: &Bound<'_, PyAny>) -> PyResult<()> {
        guard(|| arena_io::step(self, py, actions, false))
    }

    /// The screen with the robots drawn at their tracked poses, `(H, W, 3)` uint8.
    #[pyo3(signature = (world=None, width=None))]
    fn render<'py>(
        &self,
        py: Python<'py>,
        world: Option<&Bound<'py, PyAny>>,
        width: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        guard(|| {
            if let Some(w) = args::given(world) {
                args::int_in(w, "world", 0, 0)?;
            }
            let width = arena_io::render_width(width, 4096)?;
            arena_io::image(py, py.detach(|| self.lock().render(width)))
        })
    }

    #[pyo3(signature = (world=0))]
    fn episode_steps(&self, py: Python<'_>, world: usize) -> PyResult<u64> {
        check_world(world)?;
        Ok(py.detach(|| self.lock().episode_steps()))
    }

    #[pyo3(signature = (world=0))]
    fn episode(&self, py: Python<'_>, world: usize) -> PyResult<u64> {
        check_world(world)?;
        Ok(py.detach(|| self.lock().episode()))
    }

    /// The poses the loop used in the last tick `(R, 3)`: x m, y m, heading rad (tracked, latency
    /// compensated).
    #[pyo3(signature = (world=0))]
    fn poses<'py>(&self, py: Python<'py>, world: usize) -> PyResult<Bound<'py, PyAny>> {
        check_world(world)?;
        let poses = py.detach(|| colcos_sim::world::ArenaView::poses(self.lock().host()).to_vec());
        arena_io::pose_rows(py, poses)
    }

    /// The scenario actually used, as TOML.
    fn scenario_toml(&self, py: Python<'_>) -> PyResult<String> {
        guard(|| Ok(py.detach(|| self.lock().scenario().to_toml())))
    }

    #[getter]
    fn backend_name(&self) -> &'static str {
        "cpu"
    }
    #[getter]
    fn backend_info(&self) -> &'static str {
        "cpu (the host's field)"
    }

    /// What the plant measured: kind, time, the live loop's report (ticks, overruns, worst tick,
    /// shield, safety stops), the last reset's go-to.
    fn plant_info<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let (kind, time, report, goto) = py.detach(|| {
            let g = self.lock();
            (g.kind(), g.time(), g.live_report(), g.goto_report())
        });
        let d = PyDict::new(py);
        d.set_item("plant", format!("{kind:?}").to_lowercase())?;
        d.set_item("time", time)?;
        if let Some(r) = report {
            d.set_item("ticks", r.ticks)?;
            d.set_item("overruns", r.overruns)?;
            d.set_item("worst_tick_ms", r.worst_tick_ms)?;
            d.set_item("p99_tick_ms", r.p99_tick_ms)?;
            d.set_item("shield_capped", r.shield.capped)?;
            d.set_item("shield_walled", r.shield.walled)?;
            d.set_item("stops", r.stops)?;
            d.set_item("commands_sent", r.commands_sent)?;
        }
        d.set_item("goto_seconds", goto.seconds)?;
        d.set_item("goto_arrived", goto.arrived)?;
        Ok(d)
    }

    /// Stops every robot now (twin, rig): what to call when a policy fails.
    #[pyo3(signature = (reason="stopped from Python"))]
    fn stop(&self, py: Python<'_>, reason: &str) {
        py.detach(|| self.lock().stop_all(reason));
    }

    /// Stops every robot and lets go of the tracker, the link and the twin; `reset` and `step`
    /// raise from then on. Closing twice is harmless.
    #[pyo3(signature = (reason="the environment was closed"))]
    fn close(&self, py: Python<'_>, reason: &str) {
        py.detach(|| self.lock().close(reason));
    }

    /// Whether `close` was called.
    #[getter]
    fn closed(&self, py: Python<'_>) -> bool {
        py.detach(|| self.lock().is_closed())
    }
}

// SAFETY: the buffers are allocated once in LiveEnv::new and never reallocated.
unsafe impl arena_io::Arena for PyPlant {
    type Error = PlantError;
    fn py_err(e: Self::Error) -> PyErr {
        plant_err(e)
    }
    fn sizes(&self) -> (usize, usize, Option<usize>) {
        (1, self.num_agents, self.width)
    }
    fn buffers(&self) -> (BufferPtrs, EnvSpec) {
        let mut g = self.lock();
        (g.buffer_ptrs(), g.spec().clone())
    }
    /// `mask` is always None: `reset` refuses one.
    fn reset_now(&self, seed: Option<u64>, _mask: Option<&[bool]>) -> Result<(), Self::Error> {
        self.lock().reset(seed)
    }
    fn step_now(&self, actions: Actions<'_>, deferred: bool) -> Result<(), Self::Error> {
        let mut env = self.lock();
        if deferred {
            env.step_deferred(actions)
        } else {
            env.step(actions)
        }
    }
}

fn check_world(world: usize) -> PyResult<()> {
    if world != 0 {
        return Err(Kind::Task.err(format!("world = {world}: a plant has one world (0)")));
    }
    Ok(())
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyPlant>()
}
