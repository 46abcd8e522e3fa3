//! One exception tree: `ColcosError(ValueError)` and a subclass per kind of mistake.
use colcos_env::EnvError;
use pyo3::create_exception;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

create_exception!(
    colcos,
    ColcosError,
    PyValueError,
    "Base of every error colcos raises on bad input."
);
create_exception!(
    colcos,
    ScenarioError,
    ColcosError,
    "A scenario file or text could not be read, parsed or validated."
);
create_exception!(
    colcos,
    TaskError,
    ColcosError,
    "Unknown task, or an unknown or invalid task/environment parameter."
);
create_exception!(
    colcos,
    ActionError,
    ColcosError,
    "Actions of the wrong shape or dtype, non-finite, out of range, or for an unknown agent."
);
create_exception!(
    colcos,
    StateError,
    ColcosError,
    "A call that is not valid now (e.g. step before reset)."
);
create_exception!(
    colcos,
    BackendError,
    ColcosError,
    "The field backend asked for cannot be used (e.g. backend=\"gpu\" where there is no GPU adapter)."
);
create_exception!(
    colcos,
    DisplayError,
    ColcosError,
    "No window can be opened (no X/Wayland display, no GPU adapter for it, or built without it)."
);

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("ColcosError", py.get_type::<ColcosError>())?;
    m.add("ScenarioError", py.get_type::<ScenarioError>())?;
    m.add("TaskError", py.get_type::<TaskError>())?;
    m.add("ActionError", py.get_type::<ActionError>())?;
    m.add("StateError", py.get_type::<StateError>())?;
    m.add("BackendError", py.get_type::<BackendError>())?;
    m.add("DisplayError", py.get_type::<DisplayError>())?;
    Ok(())
}

/// The Python exception for an environment error.
pub fn to_py(e: EnvError) -> PyErr {
    let msg = e.to_string();
    match e {
        EnvError::Scenario(_) => ScenarioError::new_err(msg),
        EnvError::UnknownTask { .. } | EnvError::Param { .. } => TaskError::new_err(msg),
        EnvError::Action(_) => ActionError::new_err(msg),
        EnvError::State(_) => StateError::new_err(msg),
        EnvError::Backend(_) => BackendError::new_err(msg),
    }
}
