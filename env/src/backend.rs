//! The field backend of a batch's worlds: the scenario's `[field] backend` (`cpu`, `gpu`, `auto`; or
//! [`crate::EnvConfig::backend`]), resolved once per environment, as `colcos run --backend` does it.
//!
//! On the GPU, worlds whose pheromones are all grids of one spec (and whose screen shows no printed
//! obstacles) keep their fields in one resident batch for the whole environment (the vector env's GPU
//! stage: every world's field step, trail deposits and colour sensing in one dispatch sequence a
//! step); other worlds each get a backend of their own that steps their fields on the device.
//!
//! `auto` takes the GPU only where it pays: a hardware adapter (a software one such as lavapipe is
//! slower than the CPU) and at least [`AUTO_GPU_MIN_WORLDS`] worlds (a small batch does not fill a
//! GPU, and its transfers and dispatches cost more than the CPU's step); otherwise the CPU.
//!
//! The GPU needs the `gpu` feature (the Python package turns it on); without it `gpu` is an error and
//! `auto` takes the CPU.
use crate::error::{EnvError, Result};
use colcos_sim::field::BackendChoice;
use colcos_sim::scenario::Scenario;
use colcos_sim::world::World;

/// Fewest worlds for which `auto` takes a hardware GPU: on an H200 with 16 cores the batch ran `trail`
/// at 0.45x the CPU backend with 256 worlds and 1.20x with 1,024 (`benches/gpu_machine.sh`).
pub const AUTO_GPU_MIN_WORLDS: usize = 1024;

/// A resolved backend choice.
#[derive(Clone)]
pub struct EnvBackend {
    #[cfg(feature = "gpu")]
    shared: colcos_gpu::SharedBackend,
    description: String,
    gpu: bool,
    /// The worlds' grids live in the environment's resident GPU batch, not in a backend per world.
    batched: bool,
}

impl EnvBackend {
    /// Resolves `choice` for `worlds` worlds of `scenario`: `gpu` without an adapter is an
    /// [`EnvError::Backend`]; `auto` takes a hardware GPU for [`AUTO_GPU_MIN_WORLDS`] worlds or more,
    /// else the CPU.
    #[cfg(feature = "gpu")]
    pub fn resolve(choice: BackendChoice, worlds: usize, scenario: &Scenario) -> Result<Self> {
        let resolve = |choice: BackendChoice| {
            colcos_gpu::SharedBackend::resolve(choice)
                .map_err(|e| EnvError::Backend(format!("field backend {choice}: {e}")))
        };
        let shared = resolve(choice)?;
        if choice == BackendChoice::Auto
            && shared.context().is_some()
            && worlds < AUTO_GPU_MIN_WORLDS
        {
            return Ok(EnvBackend {
                shared: resolve(BackendChoice::Cpu)?,
                description: format!(
                    "cpu (auto: {worlds} worlds, the GPU pays from {AUTO_GPU_MIN_WORLDS})"
                ),
                gpu: false,
                batched: false,
            });
        }
        let mut description = shared.selection().to_string();
        let gpu = shared.context().is_some();
        let mut batched = false;
        if gpu {
            let probe = World::with_index(scenario, 0)?;
            let why = colcos_gpu::worlds::unsupported(probe.pheromones()).or_else(|| {
                probe
                    .obstacles()
                    .printed()
                    .map(|_| "the screen shows printed obstacles".to_string())
            });
            match why {
                None => {
                    batched = true;
                    description.push_str(&format!(" (the {worlds} worlds' fields in one batch)"));
                }
                Some(why) => description.push_str(&format!(" (a batch per world: {why})")),
            }
        }
        Ok(EnvBackend {
            gpu,
            shared,
            description,
            batched,
        })
    }

    /// Resolves `choice`: without the `gpu` feature, `gpu` is an error and `auto` the CPU.
    #[cfg(not(feature = "gpu"))]
    pub fn resolve(choice: BackendChoice, _worlds: usize, _scenario: &Scenario) -> Result<Self> {
        match choice {
            BackendChoice::Cpu => Ok(EnvBackend {
                description: "cpu (asked for)".into(),
                gpu: false,
                batched: false,
            }),
            BackendChoice::Auto => Ok(EnvBackend {
                description: "cpu (auto: colcos-env was built without the `gpu` feature)".into(),
                gpu: false,
                batched: false,
            }),
            BackendChoice::Gpu => Err(EnvError::Backend(
                "field backend gpu: colcos-env was built without the `gpu` feature".into(),
            )),
        }
    }

    /// `"gpu"` or `"cpu"`: what steps the grid fields.
    pub fn name(&self) -> &'static str {
        if self.gpu { "gpu" } else { "cpu" }
    }

    /// Whether the worlds' grids live in the environment's resident GPU batch.
    pub fn is_batched(&self) -> bool {
        self.batched
    }

    /// The device of the GPU batch, where the worlds' grids live in one.
    #[cfg(feature = "gpu")]
    pub(crate) fn batch_context(&self) -> Option<&std::sync::Arc<colcos_gpu::GpuContext>> {
        self.shared.context().filter(|_| self.batched)
    }

    /// After the first world is built: a GPU that has no grid field to step is reported as the CPU.
    pub(crate) fn settle(&mut self, world: &World) {
        if self.gpu && !self.batched && world.field_backend().is_none() {
            self.gpu = false;
            self.description = "cpu (no grid pheromones to step)".into();
        }
    }

    /// One line for logs: `gpu: <adapter> (...)` or `cpu (<reason>)`.
    pub fn describe(&self) -> &str {
        &self.description
    }

    /// Installs the backend in a new world (before its first step).
    pub fn install(&self, world: &mut World) -> Result<()> {
        #[cfg(feature = "gpu")]
        if !self.batched {
            self.shared
                .install(world)
                .map_err(|e| EnvError::Backend(format!("field backend: {e}")))?;
        }
        #[cfg(not(feature = "gpu"))]
        let _ = world;
        Ok(())
    }

    /// Hands a new world's grids to the GPU batch once the world is ready to step (its build and the
    /// task's settling step done on the CPU); nothing for other backends.
    pub(crate) fn hand_over(&self, world: &mut World) {
        if self.batched {
            world.set_external_grids(true);
        }
    }
}

impl std::fmt::Debug for EnvBackend {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.description)
    }
}
