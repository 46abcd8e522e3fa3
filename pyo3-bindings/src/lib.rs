//! `colcos._core`: the native module behind the `colcos` Python package. A thin layer: the batched
//! environment, baseline policies and the registries of `colcos-env` and `colcos-sim`, with one
//! exception tree. The GIL is released around every reset and step, and before any lock is taken.
use pyo3::prelude::*;

mod arena_io;
mod args;
mod baseline;
mod errors;
mod limits;
mod plant;
mod registry;
mod rig;
mod spec;
mod sweep;
mod task_hooks;
mod task_view;
mod vec_env;
mod window;

#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    // Rust's `log` messages go to Python's `logging` (logger names follow the Rust module paths,
    // `colcos_gpu.backend`). Another extension may have installed a logger first: then it keeps them.
    let _ = pyo3_log::Logger::new(m.py(), pyo3_log::Caching::LoggersAndLevels)?.install();
    errors::register(m)?;
    vec_env::register(m)?;
    plant::register(m)?;
    baseline::register(m)?;
    registry::register(m)?;
    rig::register(m)?;
    window::register(m)?;
    sweep::register(m)?;
    task_hooks::register(m)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
