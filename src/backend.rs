//! The field backend of a run: `cpu`, `gpu` or `auto` (`colcos run --backend`, scenario `field.backend`).
use anyhow::Result;
use colcos_sim::field::BackendChoice;
use colcos_sim::world::World;

/// Installs the backend `choice` in `world`; returns what was chosen, for the log (`cpu (...)` or
/// `gpu: <adapter>`). `gpu` without an adapter is an error; `auto` falls back to the CPU and says why.
#[cfg(feature = "gpu")]
pub fn install(world: &mut World, choice: BackendChoice) -> Result<String> {
    Ok(colcos_gpu::install(world, choice)
        .map_err(|e| anyhow::anyhow!("field backend {choice}: {e}"))?
        .to_string())
}

/// Without the `gpu` feature only the CPU backend exists.
#[cfg(not(feature = "gpu"))]
pub fn install(world: &mut World, choice: BackendChoice) -> Result<String> {
    world.set_field_backend(None);
    match choice {
        BackendChoice::Cpu => Ok("cpu (asked for)".into()),
        BackendChoice::Auto => Ok("cpu (auto: built without the `gpu` feature)".into()),
        BackendChoice::Gpu => {
            anyhow::bail!("field backend gpu: this colcos was built without the `gpu` feature")
        }
    }
}
