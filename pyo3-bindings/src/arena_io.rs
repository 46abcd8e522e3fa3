//! The numpy side that the batch (`VecEnv`) and a plant (`Plant`) share: views of the output
//! buffers, actions copied in, and the seed, render width, image and poses of their methods.
use crate::args;
use crate::errors::Kind;
use colcos_env::{Actions, BufferPtrs, EnvSpec, Space};
use colcos_sim::robot::Pose;
use numpy::ndarray::{ArrayView, IxDyn};
use numpy::{
    Element, PyArray, PyArray1, PyArrayMethods, PyReadonlyArrayDyn, PyUntypedArrayMethods,
};
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

/// The dict of numpy views of the output buffers that `buffers` (run with the GIL released) hands
/// out with their spec: `obs [E,N,D]`, `rewards`, `terminated`, `truncated`, `shield [E,N]`,
/// `final_obs [E,N,D]`, `final_mask [E]`, and `state [E,S]` and `patch [E,N,P,P,3]` where the spec
/// has them. Each view keeps `owner` alive.
///
/// # Safety
/// The buffers must be those of an `Outputs` made for the spec, allocated once and never reallocated
/// for as long as `owner` lives.
pub(crate) unsafe fn views<'py>(
    owner: &Bound<'py, PyAny>,
    buffers: impl FnOnce() -> (BufferPtrs, EnvSpec) + Send,
) -> PyResult<Bound<'py, PyDict>> {
    let py = owner.py();
    let (Ptrs(bufs), spec) = py.detach(|| {
        let (bufs, spec) = buffers();
        (Ptrs(bufs), spec)
    });
    let d = PyDict::new(py);
    let (e, n) = (spec.num_envs, spec.num_agents);
    let obs = vec![e, n, spec.observation.flat_len()];
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

/// An RGB image as a uint8 array `(H, W, 3)`.
pub(crate) fn image<'py>(py: Python<'py>, img: image::RgbImage) -> PyResult<Bound<'py, PyAny>> {
    let (w, h) = (img.width() as usize, img.height() as usize);
    let flat = PyArray1::from_vec(py, img.into_raw());
    Ok(flat.reshape([h, w, 3])?.into_any())
}

/// Poses as a float32 array `(R, 3)`: x m, y m, heading rad.
pub(crate) fn pose_rows<'py>(py: Python<'py>, poses: Vec<Pose>) -> PyResult<Bound<'py, PyAny>> {
    let flat: Vec<f32> = (poses.iter())
        .flat_map(|p| [p.pos.x, p.pos.y, p.heading])
        .collect();
    Ok(PyArray1::from_vec(py, flat)
        .reshape([poses.len(), 3])?
        .into_any())
}
