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

/// Declares [`Kind`] and its Python classes from one list, in order, parents first: each entry's
/// doc comment is its class's docstring, `< Parent` its colcos base and `+ "Builtin"` its builtin
/// base.
macro_rules! kinds {
    ($($(#[doc = $doc:literal])+ $kind:ident = $name:literal $(< $parent:ident)? $(+ $builtin:literal)?;)+) => {
        /// A kind of error: one Python class each.
        #[derive(Clone, Copy, Debug, PartialEq, Eq)]
        pub enum Kind {
            $($(#[doc = $doc])+ $kind,)+
        }

        /// Every class: kind, class name, parent colcos class, builtin base, docstring.
        const CLASSES: &[Class] = &[
            $((Kind::$kind, $name, kinds!(@opt $(Kind::$parent)?), kinds!(@opt $($builtin)?), concat!($($doc, "\n"),+)),)+
        ];
    };
    (@opt) => { None };
    (@opt $v:expr) => { Some($v) };
}

type Class = (
    Kind,
    &'static str,
    Option<Kind>,
    Option<&'static str>,
    &'static str,
);

kinds! {
    /// Base of every error colcos raises on bad input (a ValueError).
    Colcos = "ColcosError" + "ValueError";
    /// A scenario file or text could not be read, parsed or validated.
    Scenario = "ScenarioError" < Colcos;
    /// Unknown task, or an unknown or invalid task/environment argument (named in the message).
    Task = "TaskError" < Colcos;
    /// Actions of the wrong shape, non-finite, out of range, or for an unknown agent.
    Action = "ActionError" < Colcos;
    /// A call that is not valid now (e.g. step before reset); also a RuntimeError.
    State = "StateError" < Colcos + "RuntimeError";
    /// The field backend asked for cannot be used (e.g. backend="gpu" where there is no GPU adapter).
    Backend = "BackendError" < Colcos;
    /// No window can be opened (no X/Wayland display, no GPU adapter for it, or built without it).
    Display = "DisplayError" < Colcos;
    /// An argument of the wrong type (e.g. seed='3', continuous='False'); also a TypeError.
    ArgumentType = "ArgumentTypeError" < Task + "TypeError";
    /// An action of the wrong type (None, a string, a dict, ...); also a TypeError.
    ActionType = "ActionTypeError" < Action + "TypeError";
    /// An action for an agent that does not exist; also a KeyError.
    UnknownAgent = "UnknownAgentError" < Action + "KeyError";
    /// A bug inside colcos, caught before it could take the interpreter down; please report it.
    Internal = "InternalError" < Colcos + "RuntimeError";
    /// A twin's or rig's tracker or robot link cannot be reached (the URL and the reason are named;
    /// the robots were told to stop); also a ConnectionError.
    Unreachable = "PlantUnreachableError" < State + "ConnectionError";
}

static TYPES: PyOnceLock<Vec<Py<PyType>>> = PyOnceLock::new();

fn make_types(py: Python<'_>) -> PyResult<Vec<Py<PyType>>> {
    let builtins = py.import("builtins")?;
    let type_fn = builtins.getattr("type")?;
    // KeyError quotes its message in str(); the colcos classes print it as given.
    let plain_str = builtins.getattr("BaseException")?.getattr("__str__")?;
    let mut made: Vec<Py<PyType>> = Vec::with_capacity(CLASSES.len());
    for &(kind, name, parent, builtin, doc) in CLASSES {
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
        // One line per doc comment line, each with its leading space.
        let doc: Vec<&str> = doc.lines().map(str::trim).collect();
        dict.set_item("__doc__", doc.join(" "))?;
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
    for &(kind, name, ..) in CLASSES {
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
