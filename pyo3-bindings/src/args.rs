//! Arguments from Python, checked one way everywhere: each takes any object and returns the value
//! or a colcos error naming the argument and what was given (never pyo3's bare `TypeError` or
//! `OverflowError`). Python numbers and numpy scalars are accepted alike; booleans are not numbers.
use crate::errors::Kind;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyString};

/// `repr(value)`, shortened: messages quote what was given without flooding the terminal.
pub fn show(v: &Bound<'_, PyAny>) -> String {
    let r = v
        .repr()
        .map(|s| s.to_string())
        .unwrap_or_else(|_| "<unprintable>".into());
    if r.chars().count() > 80 {
        let head: String = r.chars().take(77).collect();
        format!("{head}...")
    } else {
        r
    }
}

fn type_name(v: &Bound<'_, PyAny>) -> String {
    v.get_type()
        .name()
        .map(|n| n.to_string())
        .unwrap_or_else(|_| "?".into())
}

/// True for Python's and numpy's booleans.
pub fn is_bool(v: &Bound<'_, PyAny>) -> bool {
    v.is_instance_of::<PyBool>() || matches!(type_name(v).as_str(), "bool" | "bool_")
}

/// An integer in `lo..=hi`: a Python int or a numpy integer scalar (`__index__`), not a bool.
pub fn int_in(v: &Bound<'_, PyAny>, name: &str, lo: u64, hi: u64) -> PyResult<u64> {
    let range = || {
        if hi == u64::MAX {
            format!("an integer in {lo}..=2**64-1")
        } else {
            format!("an integer in {lo}..={hi}")
        }
    };
    let as_int = if is_bool(v) || v.is_instance_of::<PyFloat>() || v.is_instance_of::<PyString>() {
        None
    } else if v.is_instance_of::<PyInt>() {
        Some(v.clone())
    } else if v.hasattr("__index__").unwrap_or(false) {
        v.call_method0("__index__").ok()
    } else {
        None
    };
    let Some(i) = as_int else {
        return Err(Kind::ArgumentType.err(format!(
            "{name} must be {}, got {} ({})",
            range(),
            show(v),
            type_name(v)
        )));
    };
    match i.extract::<u64>() {
        Ok(x) if (lo..=hi).contains(&x) => Ok(x),
        _ => Err(Kind::Task.err(format!("{name} must be {}, got {}", range(), show(v)))),
    }
}

/// A seed: any integer in `0..=2**64-1`.
pub fn seed(v: &Bound<'_, PyAny>, name: &str) -> PyResult<u64> {
    int_in(v, name, 0, u64::MAX)
}

/// A flag: `True`/`False` (or a numpy bool), never a truthy string or number.
pub fn flag(v: &Bound<'_, PyAny>, name: &str) -> PyResult<bool> {
    if is_bool(v)
        && let Ok(b) = v.extract::<bool>()
    {
        return Ok(b);
    }
    Err(Kind::ArgumentType.err(format!(
        "{name} must be True or False, got {} ({})",
        show(v),
        type_name(v)
    )))
}

/// A finite real number (int, float or numpy scalar; not a bool or a string).
pub fn real(v: &Bound<'_, PyAny>, name: &str) -> PyResult<f64> {
    let x = if is_bool(v) || v.is_instance_of::<PyString>() {
        None
    } else {
        v.extract::<f64>().ok()
    };
    let Some(x) = x else {
        return Err(Kind::ArgumentType.err(format!(
            "{name} must be a number, got {} ({})",
            show(v),
            type_name(v)
        )));
    };
    if !x.is_finite() {
        return Err(Kind::Task.err(format!("{name} must be finite, got {}", show(v))));
    }
    Ok(x)
}

/// A string.
pub fn text(v: &Bound<'_, PyAny>, name: &str) -> PyResult<String> {
    match v.cast::<PyString>() {
        Ok(s) => Ok(s.to_str()?.to_owned()),
        Err(_) => Err(Kind::ArgumentType.err(format!(
            "{name} must be a str, got {} ({})",
            show(v),
            type_name(v)
        ))),
    }
}

/// A string or None.
pub fn opt_text(v: Option<&Bound<'_, PyAny>>, name: &str) -> PyResult<Option<String>> {
    match v {
        Some(v) if !v.is_none() => text(v, name).map(Some),
        _ => Ok(None),
    }
}

/// `v`, unless it is absent or None.
pub fn given<'a, 'py>(v: Option<&'a Bound<'py, PyAny>>) -> Option<&'a Bound<'py, PyAny>> {
    v.filter(|v| !v.is_none())
}

/// A path: a str or an `os.PathLike`.
pub fn path(v: &Bound<'_, PyAny>, name: &str) -> PyResult<std::path::PathBuf> {
    v.extract().map_err(|_| {
        Kind::ArgumentType.err(format!(
            "{name} must be a path (str or os.PathLike), got {}",
            show(v)
        ))
    })
}

/// A constructor's keyword arguments, taken out one by one by name: those left at the end were not
/// expected.
pub struct Keywords<'py> {
    left: Bound<'py, PyDict>,
    class: &'static str,
}

impl<'py> Keywords<'py> {
    /// The arguments `kw` of a constructor of `class` (a copy: the caller's dict is left alone).
    pub fn new(
        py: Python<'py>,
        kw: Option<&Bound<'py, PyDict>>,
        class: &'static str,
    ) -> PyResult<Self> {
        let left = match kw {
            Some(d) => d.copy()?,
            None => PyDict::new(py),
        };
        Ok(Keywords { left, class })
    }

    /// Argument `name`, None where it was not given or given as None.
    pub fn take(&self, name: &str) -> PyResult<Option<Bound<'py, PyAny>>> {
        let v = self.left.get_item(name)?;
        if v.is_some() {
            self.left.del_item(name)?;
        }
        Ok(v.filter(|v| !v.is_none()))
    }

    /// Argument `name`, a string or None.
    pub fn text(&self, name: &str) -> PyResult<Option<String>> {
        self.take(name)?.map(|v| text(&v, name)).transpose()
    }

    /// Refuses the first argument not taken, as Python refuses an unknown keyword.
    pub fn finish(self) -> PyResult<()> {
        match self.left.keys().iter().next() {
            Some(k) => Err(Kind::ArgumentType.err(format!(
                "{}() got an unexpected keyword argument {}",
                self.class,
                show(&k)
            ))),
            None => Ok(()),
        }
    }
}

/// Runs `f`, turning a Rust panic into `colcos.InternalError` (a `ColcosError`): pyo3 would raise a
/// `PanicException`, a `BaseException` that `except Exception` does not catch.
pub fn guard<T>(f: impl FnOnce() -> PyResult<T>) -> PyResult<T> {
    match std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)) {
        Ok(r) => r,
        Err(payload) => {
            let what = payload
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| payload.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown panic".into());
            Err(Kind::Internal.err(format!(
                "internal error in colcos (a bug, please report it): {what}"
            )))
        }
    }
}
