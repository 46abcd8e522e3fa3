//! The numpy side that the batch (`VecEnv`) and a plant (`Plant`) share: views of the output
//! buffers, reset and step with their arguments checked, and the seed, render width, image and poses
//! of their other methods.
use crate::args;
use crate::errors::Kind;
use colcos_env::{Actions, BufferPtrs, EnvSpec, Space};
use colcos_sim::robot::Pose;
use numpy::ndarray::{ArrayView, IntoDimension, IxDyn};
use numpy::{
    Element, PyArray, PyArray1, PyArrayMethods, PyReadonlyArrayDyn, PyUntypedArrayMethods,
};
use pyo3::PyClass;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// Raw buffer pointers carried out of a `detach` closure.
struct Ptrs<T>(T);
// SAFETY: plain addresses of buffers owned by the env, only dereferenced with the GIL held while the
// env is alive (see `views`).
unsafe impl<T> Send for Ptrs<T> {}

/// A numpy view of the elements at `ptr` shaped `shape`, keeping `owner` alive.
///
/// # Safety
/// `ptr..ptr + product(shape)` must stay valid for as long as `owner` lives.
unsafe fn view<'py, T: Element>(
    owner: &Bound<'py, PyAny>,
    ptr: *mut T,
    shape: Vec<usize>,
) -> PyResult<Bound<'py, PyAny>> {
    let a = unsafe { ArrayView::from_shape_ptr(IxDyn(&shape), ptr as *const T) };
    Ok(unsafe { PyArray::borrow_from_array(&a, owner.clone()) }.into_any())
}

/// A pyclass over an arena's output buffers (the batch of worlds, a plant's one arena): what the
/// shared `views`, `reset` and `step` below need of it. `buffers`, `reset_now` and `step_now` take
/// its lock: call them with the GIL released.
///
/// # Safety
/// `buffers` must hand out the buffers of an `Outputs` made for the spec it returns, allocated once
/// and never reallocated for as long as the object lives.
pub(crate) unsafe trait Arena: PyClass + Sync {
    /// The arena's own error, made a Python exception (with the GIL held) by `py_err`.
    type Error: Send;
    fn py_err(e: Self::Error) -> PyErr;
    /// Worlds, agents per world and the width of a continuous action row (None: discrete), fixed
    /// at construction.
    fn sizes(&self) -> (usize, usize, Option<usize>);
    fn buffers(&self) -> (BufferPtrs, EnvSpec);
    fn reset_now(&self, seed: Option<u64>, mask: Option<&[bool]>) -> Result<(), Self::Error>;
    /// A step, or its first half only (`deferred`: a task written in Python concludes it).
    fn step_now(&self, actions: Actions<'_>, deferred: bool) -> Result<(), Self::Error>;
}

/// The dict of numpy views of `slf`'s output buffers: `obs [E,N,D]`, `rewards`, `terminated`,
/// `truncated`, `shield [E,N]`, `final_obs [E,N,D]`, `final_mask [E]`, and `state [E,S]` and
/// `patch [E,N,P,P,3]` where the spec has them. Each view keeps `slf` alive.
pub(crate) fn views<'py, A: Arena>(slf: &Bound<'py, A>) -> PyResult<Bound<'py, PyDict>> {
    let py = slf.py();
    let owner = slf.as_any();
    let class = slf.borrow();
    let me: &A = &class;
    let (Ptrs(bufs), spec) = py.detach(|| {
        let (bufs, spec) = me.buffers();
        (Ptrs(bufs), spec)
    });
    let d = PyDict::new(py);
    let (e, n) = (spec.num_envs, spec.num_agents);
    let obs = vec![e, n, spec.observation.flat_len()];
    // SAFETY: `Arena`'s contract: the buffers stay where they are while `owner` lives.
    unsafe {
        d.set_item("obs", view(owner, bufs.obs, obs.clone())?)?;
        d.set_item("rewards", view(owner, bufs.rewards, vec![e, n])?)?;
        d.set_item("terminated", view(owner, bufs.terminated, vec![e, n])?)?;
        d.set_item("truncated", view(owner, bufs.truncated, vec![e, n])?)?;
        d.set_item("shield", view(owner, bufs.shield, vec![e, n])?)?;
        d.set_item("final_obs", view(owner, bufs.final_obs, obs)?)?;
        d.set_item("final_mask", view(owner, bufs.final_mask, vec![e])?)?;
        if let Some(s) = &spec.state {
            d.set_item("state", view(owner, bufs.state, vec![e, s.flat_len()])?)?;
        }
        if let Some(Space::Box { shape, .. }) = &spec.patch {
            let patch = vec![e, n, shape[0], shape[1], shape[2]];
            d.set_item("patch", view(owner, bufs.patch, patch)?)?;
        }
    }
    Ok(d)
}

/// `reset(seed=None, mask=None)`: the seed checked, then the mask (a 1-D bool array of length
/// num_envs), then the arena reset with the GIL released.
pub(crate) fn reset<A: Arena>(
    me: &A,
    py: Python<'_>,
    seed: Option<&Bound<'_, PyAny>>,
    mask: Option<&Bound<'_, PyAny>>,
) -> PyResult<()> {
    let seed = opt_seed(seed)?;
    let mask = args::given(mask)
        .map(|m| reset_mask(m, me.sizes().0))
        .transpose()?;
    py.detach(|| me.reset_now(seed, mask.as_deref()))
        .map_err(A::py_err)
}

/// A reset mask: a 1-D bool array (or sequence of bools) of length `e` (num_envs).
fn reset_mask(m: &Bound<'_, PyAny>, e: usize) -> PyResult<Vec<bool>> {
    let a: PyReadonlyArrayDyn<'_, bool> = m.extract().map_err(|_| {
        Kind::ArgumentType.err(format!(
            "reset mask must be a bool numpy array of shape ({e},), got {}",
            args::show(m)
        ))
    })?;
    if a.shape() != [e] {
        return Err(Kind::Task.err(format!(
            "reset mask must have shape ({e},) = (num_envs,), got shape {:?}",
            a.shape()
        )));
    }
    Ok(flat(&a))
}

/// `step(actions)`: the actions checked and copied with the GIL held, then the arena stepped (its
/// first half only if `deferred`) with it released.
pub(crate) fn step<A: Arena>(
    me: &A,
    py: Python<'_>,
    actions: &Bound<'_, PyAny>,
    deferred: bool,
) -> PyResult<()> {
    let (e, n, width) = me.sizes();
    let acts = owned_actions(actions, e, n, width)?;
    py.detach(|| me.step_now(acts.actions(), deferred))
        .map_err(A::py_err)
}

/// Actions copied out of numpy (before the env's lock is taken, with the GIL held).
pub(crate) enum Owned {
    Continuous(Vec<f32>),
    Discrete(Vec<i64>),
}

impl Owned {
    /// The actions as the env takes them.
    pub(crate) fn actions(&self) -> Actions<'_> {
        match self {
            Owned::Discrete(a) => Actions::Discrete(a),
            Owned::Continuous(a) => Actions::Continuous(a),
        }
    }
}

/// The width of a continuous action row, or None for discrete actions.
pub(crate) fn action_width(space: &Space) -> Option<usize> {
    match space {
        Space::Box { shape, .. } => Some(shape.iter().product()),
        Space::Discrete { .. } => None,
    }
}

/// `actions` checked and copied: int64 `[e, n]` (discrete, `width` None) or float32 `[e, n, width]`,
/// C-contiguous or not.
pub(crate) fn owned_actions(
    actions: &Bound<'_, PyAny>,
    e: usize,
    n: usize,
    width: Option<usize>,
) -> PyResult<Owned> {
    let Some(w) = width else {
        let a: PyReadonlyArrayDyn<'_, i64> = actions.extract().map_err(|_| {
            Kind::ActionType.err(format!(
                "discrete actions must be an int64 numpy array of shape ({e}, {n}) = \
                 (num_envs, num_agents), got {}",
                args::show(actions)
            ))
        })?;
        if a.shape() != [e, n] {
            return Err(Kind::Action.err(format!(
                "actions have shape {:?}, expected ({e}, {n}) = (num_envs, num_agents)",
                a.shape()
            )));
        }
        return Ok(Owned::Discrete(flat(&a)));
    };
    let row = if w == 2 {
        "wheels".to_string()
    } else {
        format!("2 wheels + {} deposit rates", w - 2)
    };
    let a: PyReadonlyArrayDyn<'_, f32> = actions.extract().map_err(|_| {
        Kind::ActionType.err(format!(
            "continuous actions must be a float32 numpy array of shape ({e}, {n}, {w}) = \
             (num_envs, num_agents, {row}), got {}",
            args::show(actions)
        ))
    })?;
    if a.shape() != [e, n, w] {
        return Err(Kind::Action.err(format!(
            "actions have shape {:?}, expected ({e}, {n}, {w}) = (num_envs, num_agents, {row})",
            a.shape()
        )));
    }
    Ok(Owned::Continuous(match a.as_slice() {
        Ok(src) => src.to_vec(),
        Err(_) => flat(&a),
    }))
}

/// The elements of `a` in order, C-contiguous or not.
pub(crate) fn flat<T: Element + Copy>(a: &PyReadonlyArrayDyn<'_, T>) -> Vec<T> {
    a.as_array().iter().copied().collect()
}

/// A seed argument: None, or an integer in `0..=2**64-1`.
pub(crate) fn opt_seed(seed: Option<&Bound<'_, PyAny>>) -> PyResult<Option<u64>> {
    args::given(seed).map(|s| args::seed(s, "seed")).transpose()
}

/// A render width argument in `16..=max` pixels, 640 if None.
pub(crate) fn render_width(width: Option<&Bound<'_, PyAny>>, max: u64) -> PyResult<u32> {
    Ok(match args::given(width) {
        Some(x) => args::int_in(x, "width", 16, max)? as u32,
        None => 640,
    })
}

/// `values` (in C order) as a numpy array of shape `shape`, whose product must be their count.
pub(crate) fn shaped<'py, T: Element, D: IntoDimension>(
    py: Python<'py>,
    values: Vec<T>,
    shape: D,
) -> PyResult<Bound<'py, PyAny>> {
    Ok(PyArray1::from_vec(py, values).reshape(shape)?.into_any())
}

/// An RGB image as a uint8 array `(H, W, 3)`.
pub(crate) fn image<'py>(py: Python<'py>, img: image::RgbImage) -> PyResult<Bound<'py, PyAny>> {
    let (w, h) = (img.width() as usize, img.height() as usize);
    shaped(py, img.into_raw(), [h, w, 3])
}

/// Poses as a float32 array `(R, 3)`: x m, y m, heading rad.
pub(crate) fn pose_rows<'py>(py: Python<'py>, poses: Vec<Pose>) -> PyResult<Bound<'py, PyAny>> {
    let flat: Vec<f32> = (poses.iter())
        .flat_map(|p| [p.pos.x, p.pos.y, p.heading])
        .collect();
    shaped(py, flat, [poses.len(), 3])
}
