//! The seam for other field backends (the wgpu backend lives in the `colcos-gpu` crate, which depends on
//! this one): a [`FieldBackend`] installed in a [`crate::world::World`] steps its pheromones instead of
//! [`super::Pheromone::step`]. The CPU backend is the default and needs nothing installed.
use super::Pheromone;
use serde::{Deserialize, Serialize};

/// Which backend steps the grid fields: the scenario key `field.backend`, `colcos run --backend`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum BackendChoice {
    /// The CPU backend ([`super::GridField::step`]).
    #[default]
    Cpu,
    /// A GPU through wgpu; an error where there is no adapter (software adapters count).
    Gpu,
    /// A hardware GPU when there is one, else the CPU (a software adapter such as llvmpipe is slower
    /// than the CPU backend, so `auto` does not take it).
    Auto,
}

impl BackendChoice {
    pub fn as_str(&self) -> &'static str {
        match self {
            BackendChoice::Cpu => "cpu",
            BackendChoice::Gpu => "gpu",
            BackendChoice::Auto => "auto",
        }
    }
}

impl std::str::FromStr for BackendChoice {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s.to_ascii_lowercase().as_str() {
            "cpu" => Ok(BackendChoice::Cpu),
            "gpu" => Ok(BackendChoice::Gpu),
            "auto" => Ok(BackendChoice::Auto),
            other => Err(format!(
                "unknown backend {other:?} (expected cpu, gpu or auto)"
            )),
        }
    }
}

impl std::fmt::Display for BackendChoice {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

/// Steps a world's pheromones in place of the CPU.
///
/// After [`FieldBackend::step`] the pheromones' CPU values must be current (the world's injection and
/// sensors read them), and equal to what [`Pheromone::step`] would give, to the backend's stated
/// tolerance. A backend that fails must still step the pheromones (e.g. by falling back to the CPU).
pub trait FieldBackend: Send {
    /// One line for logs, e.g. `gpu: NVIDIA H200 (DiscreteGpu, Vulkan)`.
    fn describe(&self) -> String;
    /// Advances every pheromone by `dt` seconds.
    fn step(&mut self, pheromones: &mut [Pheromone], dt: f32);
}
