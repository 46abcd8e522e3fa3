//! The field backend of a run: `cpu`, `gpu` or `auto` (`colcos run --backend`, scenario `field.backend`).
use anyhow::Result;
use colcos_sim::field::BackendChoice;
use colcos_sim::world::World;

/// Installs the backend `choice` in `world`; returns what was chosen, for the log (`cpu (...)` or
/// `gpu: <adapter>`). `gpu` without an adapter is an error; `auto` falls back to the CPU and says why.
pub fn install(world: &mut World, choice: BackendChoice) -> Result<String> {
    try_install(world, choice).map_err(|e| anyhow::anyhow!("field backend {choice}: {e}"))
}

/// [`install`] with the bare reason on failure, for callers that name the backend themselves (the run
/// library's error says `field backend <choice>: ...`).
#[cfg(feature = "gpu")]
pub fn try_install(world: &mut World, choice: BackendChoice) -> Result<String, String> {
    colcos_gpu::install(world, choice)
        .map(|s| s.to_string())
        .map_err(|e| e.to_string())
}

/// Without the `gpu` feature only the CPU backend exists.
#[cfg(not(feature = "gpu"))]
pub fn try_install(world: &mut World, choice: BackendChoice) -> Result<String, String> {
    world.set_field_backend(None);
    match choice {
        BackendChoice::Cpu => Ok("cpu (asked for)".into()),
        BackendChoice::Auto => Ok("cpu (auto: built without the `gpu` feature)".into()),
        BackendChoice::Gpu => Err("this colcos was built without the `gpu` feature".into()),
    }
}
