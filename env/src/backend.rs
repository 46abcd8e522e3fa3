//! The field backend of a batch's worlds: the scenario's `[field] backend` (`cpu`, `gpu`, `auto`; or
//! [`crate::EnvConfig::backend`]), resolved once per environment, as `colcos run --backend` does it,
//! and installed in every world the environment builds (one device for all of them).
//!
//! The GPU needs the `gpu` feature (the Python package turns it on); without it `gpu` is an error and
//! `auto` takes the CPU.
use crate::error::{EnvError, Result};
use colcos_sim::field::BackendChoice;
use colcos_sim::world::World;

/// A resolved backend choice.
#[derive(Clone)]
pub struct EnvBackend {
    #[cfg(feature = "gpu")]
    shared: colcos_gpu::SharedBackend,
    description: String,
    gpu: bool,
}

impl EnvBackend {
    /// Resolves `choice`: `gpu` without an adapter is an [`EnvError::Backend`]; `auto` takes a
    /// hardware GPU, else the CPU.
    pub fn resolve(choice: BackendChoice) -> Result<Self> {
        #[cfg(feature = "gpu")]
        {
            let shared = colcos_gpu::SharedBackend::resolve(choice)
                .map_err(|e| EnvError::Backend(format!("field backend {choice}: {e}")))?;
            let description = shared.selection().to_string();
            Ok(EnvBackend {
                gpu: shared.context().is_some(),
                shared,
                description,
            })
        }
        #[cfg(not(feature = "gpu"))]
        match choice {
            BackendChoice::Cpu => Ok(EnvBackend {
                description: "cpu (asked for)".into(),
                gpu: false,
            }),
            BackendChoice::Auto => Ok(EnvBackend {
                description: "cpu (auto: colcos-env was built without the `gpu` feature)".into(),
                gpu: false,
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

    /// After the first world is built: a GPU that has no grid field to step is reported as the CPU.
    pub(crate) fn settle(&mut self, world: &World) {
        if self.gpu && world.field_backend().is_none() {
            self.gpu = false;
            self.description = "cpu (no grid pheromones to step)".into();
        }
    }

    /// One line for logs: `gpu: <adapter>` or `cpu (<reason>)`.
    pub fn describe(&self) -> &str {
        &self.description
    }

    /// Installs the backend in a new world.
    pub fn install(&self, world: &mut World) -> Result<()> {
        #[cfg(feature = "gpu")]
        self.shared
            .install(world)
            .map_err(|e| EnvError::Backend(format!("field backend: {e}")))?;
        #[cfg(not(feature = "gpu"))]
        let _ = world;
        Ok(())
    }
}

impl std::fmt::Debug for EnvBackend {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.description)
    }
}
