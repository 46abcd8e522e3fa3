//! One exception tree. `ColcosError` (a `ValueError`) is the base of every error the package raises;
//! each subclass also subclasses the builtin that matches its kind of mistake, so that both
//! `except colcos.ActionError` and `except TypeError` catch a `None` action.
//!
//! The classes are made at import with Python's `type()`, as several take two bases (which
//! `create_exception!` cannot), and are kept for the life of the interpreter.
use colcos_env::EnvError;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::{PyDict, PyTuple, PyType};

/// A kind of error: one Python class each.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    Colcos,
    Scenario,
    Task,
    Action,
    State,
    Backend,
    Display,
    ArgumentType,
    ActionType,
    UnknownAgent,
    Internal,
    Unreachable,
}

/// (kind, class name, parent colcos class, extra builtin base, docstring).
type Class = (
    Kind,
    &'static str,
    Option<Kind>,
    Option<&'static str>,
    &'static str,
);

/// Every class, parents first, in the order of [`Kind`].
const CLASSES: [Class; 12] = [
    (
        Kind::Colcos,
        "ColcosError",
        None,
        Some("ValueError"),
        "Base of every error colcos raises on bad input (a ValueError).",
    ),
    (
        Kind::Scenario,
        "ScenarioError",
        Some(Kind::Colcos),
        None,
        "A scenario file or text could not be read, parsed or validated.",
    ),
    (
        Kind::Task,
        "TaskError",
        Some(Kind::Colcos),
        None,
        "Unknown task, or an unknown or invalid task/environment argument (named in the message).",
    ),
    (
        Kind::Action,
        "ActionError",
        Some(Kind::Colcos),
        None,
        "Actions of the wrong shape, non-finite, out of range, or for an unknown agent.",
    ),
    (
        Kind::State,
        "StateError",
        Some(Kind::Colcos),
        Some("RuntimeError"),
        "A call that is not valid now (e.g. step before reset); also a RuntimeError.",
    ),
    (
        Kind::Backend,
        "BackendError",
        Some(Kind::Colcos),
        None,
        "The field backend asked for cannot be used (e.g. backend=\"gpu\" where there is no GPU adapter).",
    ),
    (
        Kind::Display,
        "DisplayError",
        Some(Kind::Colcos),
        None,
        "No window can be opened (no X/Wayland display, no GPU adapter for it, or built without it).",
    ),
    (
        Kind::ArgumentType,
        "ArgumentTypeError",
        Some(Kind::Task),
        Some("TypeError"),
        "An argument of the wrong type (e.g. seed='3', continuous='False'); also a TypeError.",
    ),
    (
        Kind::ActionType,
        "ActionTypeError",
        Some(Kind::Action),
        Some("TypeError"),
        "An action of the wrong type (None, a string, a dict, ...); also a TypeError.",
    ),
    (
        Kind::UnknownAgent,
        "UnknownAgentError",
        Some(Kind::Action),
        Some("KeyError"),
        "An action for an agent that does not exist; also a KeyError.",
    ),
    (
        Kind::Internal,
        "InternalError",
        Some(Kind::Colcos),
        Some("RuntimeError"),
        "A bug inside colcos, caught before it could take the interpreter down; please report it.",
    ),
    (
        Kind::Unreachable,
        "PlantUnreachableError",
        Some(Kind::State),
        Some("ConnectionError"),
        "A twin's or rig's tracker or robot link cannot be reached (the URL and the reason are named; \
         the robots were told to stop); also a ConnectionError.",
    ),
];

static TYPES: PyOnceLock<Vec<Py<PyType>>> = PyOnceLock::new();

fn make_types(py: Python<'_>) -> PyResult<Vec<Py<PyType>>> {
    let builtins = py.import("builtins")?;
    let type_fn = builtins.getattr("type")?;
    // KeyError quotes its message in str(); the colcos classes print it as given.
    let plain_str = builtins.getattr("BaseException")?.getattr("__str__")?;
    let mut made: Vec<Py<PyType>> = Vec::with_capacity(CLASSES.len());
    for (kind, name, parent, builtin, doc) in CLASSES {
        let mut bases: Vec<Bound<'_, PyAny>> = Vec::new();
        if let Some(p) = parent {
            bases.push(made[p as usize].bind(py).clone().into_any());
        }
        if let Some(b) = builtin {
            bases.push(builtins.getattr(b)?);
        }
        debug_assert_eq!(made.len(), kind as usize);
        let dict = PyDict::new(py);
        dict.set_item("__module__", "colcos")?;
        dict.set_item("__doc__", doc)?;
        dict.set_item("__str__", &plain_str)?;
        let ty = type_fn.call1((name, PyTuple::new(py, bases)?, dict))?;
        made.push(ty.cast_into::<PyType>()?.unbind());
    }
    Ok(made)
}

impl Kind {
    /// The Python class of this kind.
    pub fn class<'py>(self, py: Python<'py>) -> PyResult<Bound<'py, PyType>> {
        let types = TYPES.get_or_try_init(py, || make_types(py))?;
        Ok(types[self as usize].bind(py).clone())
    }

    /// An exception of this kind with message `msg`.
    pub fn err(self, msg: impl Into<String>) -> PyErr {
        let msg = msg.into();
        Python::attach(|py| match self.class(py) {
            Ok(ty) => PyErr::from_type(ty, msg),
            // Only if the classes cannot be made at all (the interpreter is shutting down).
            Err(_) => PyValueError::new_err(msg),
        })
    }
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    for (kind, name, ..) in CLASSES {
        m.add(name, kind.class(py)?)?;
    }
    Ok(())
}

/// The Python exception for an environment error.
pub fn to_py(e: EnvError) -> PyErr {
    let msg = e.to_string();
    match e {
        EnvError::Scenario(_) => Kind::Scenario.err(msg),
        EnvError::UnknownTask { .. } | EnvError::Param { .. } => Kind::Task.err(msg),
        EnvError::Action(_) => Kind::Action.err(msg),
        EnvError::State(_) => Kind::State.err(msg),
        EnvError::Backend(_) => Kind::Backend.err(msg),
    }
}
