//! `colcos._core.Window`: the display window of `render_mode="human"` (the `colcos-display` crate's
//! `Viewer`: a window on a display thread, fed images from Python, paced to the field's rate).
//! The viewer's lock is only taken with the GIL released.
use crate::args::{self, guard};
use crate::errors::Kind;
use numpy::{PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::prelude::*;
use std::sync::{Mutex, MutexGuard};

/// Widest or tallest window image, px.
const MAX_SIDE: u64 = 16_384;

#[cfg(feature = "display")]
type Viewer = colcos_display::Viewer;
/// Stands for the viewer in a build without the `display` feature (never made).
#[cfg(not(feature = "display"))]
struct Viewer;

#[pyclass(module = "colcos._core", name = "Window", frozen)]
pub struct PyWindow {
    viewer: Mutex<Option<Viewer>>,
}

impl PyWindow {
    /// The viewer. Call only with the GIL released.
    fn lock(&self) -> MutexGuard<'_, Option<Viewer>> {
        self.viewer.lock().unwrap_or_else(|p| p.into_inner())
    }
}

#[pymethods]
impl PyWindow {
    /// Opens a window for images of `width x height` pixels, shown at most `fps` times a second.
    /// Raises `colcos.DisplayError` where no window can be opened.
    #[new]
    #[pyo3(signature = (width, height, title=None, fps=None, vsync=None))]
    fn new(
        py: Python<'_>,
        width: &Bound<'_, PyAny>,
        height: &Bound<'_, PyAny>,
        title: Option<&Bound<'_, PyAny>>,
        fps: Option<&Bound<'_, PyAny>>,
        vsync: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        guard(|| {
            let width = args::int_in(width, "width", 1, MAX_SIDE)? as u32;
            let height = args::int_in(height, "height", 1, MAX_SIDE)? as u32;
            let title = args::opt_text(title, "title")?.unwrap_or_else(|| "colcos".into());
            let fps = match fps.filter(|f| !f.is_none()) {
                Some(f) => args::real(f, "fps")?,
                None => 50.0,
            };
            let vsync = match vsync.filter(|v| !v.is_none()) {
                Some(v) => args::flag(v, "vsync")?,
                None => true,
            };
            open(py, width, height, title, fps, vsync)
        })
    }

    /// Shows an `(H, W, 3)` or `(H, W, 4)` uint8 image (waiting, if need be, to keep to `fps`).
    /// Returns False once the window is closed (by the user or `close()`).
    fn show(&self, py: Python<'_>, image: &Bound<'_, PyAny>) -> PyResult<bool> {
        guard(|| {
            let bad = || {
                Kind::ArgumentType.err(format!(
                    "image must be an (H, W, 3) or (H, W, 4) uint8 numpy array, got {}",
                    args::show(image)
                ))
            };
            let image: PyReadonlyArrayDyn<'_, u8> = image.extract().map_err(|_| bad())?;
            let shape = image.shape().to_vec();
            let [h, w, c] = shape[..] else {
                return Err(bad());
            };
            if (c != 3 && c != 4) || h == 0 || w == 0 {
                return Err(bad());
            }
            if h as u64 > MAX_SIDE || w as u64 > MAX_SIDE {
                return Err(Kind::Display.err(format!(
                    "image of {w} x {h} pixels is larger than {MAX_SIDE} on a side"
                )));
            }
            let arr = image.as_array();
            let mut rgba = Vec::with_capacity(h * w * 4);
            for y in 0..h {
                for x in 0..w {
                    rgba.extend_from_slice(&[
                        arr[[y, x, 0]],
                        arr[[y, x, 1]],
                        arr[[y, x, 2]],
                        if c == 4 { arr[[y, x, 3]] } else { 255 },
                    ]);
                }
            }
            Ok(py.detach(|| {
                let mut g = self.lock();
                let Some(v) = g.as_mut() else {
                    return false;
                };
                show(v, rgba, (w as u32, h as u32))
            }))
        })
    }

    /// Closes the window (closing twice is harmless).
    fn close(&self, py: Python<'_>) -> PyResult<()> {
        guard(|| {
            py.detach(|| {
                let v = self.lock().take();
                close(v);
            });
            Ok(())
        })
    }

    /// Whether the window is still open.
    #[getter]
    fn is_open(&self, py: Python<'_>) -> PyResult<bool> {
        guard(|| Ok(py.detach(|| self.lock().as_ref().is_some_and(is_open))))
    }

    /// Frames presented so far.
    #[getter]
    fn presented(&self, py: Python<'_>) -> PyResult<u64> {
        guard(|| Ok(py.detach(|| self.lock().as_ref().map_or(0, presented))))
    }
}

#[cfg(feature = "display")]
fn open(
    py: Python<'_>,
    width: u32,
    height: u32,
    title: String,
    fps: f64,
    vsync: bool,
) -> PyResult<PyWindow> {
    let period = if fps > 0.0 {
        std::time::Duration::from_secs_f64(1.0 / fps)
    } else {
        std::time::Duration::ZERO
    };
    let opts = colcos_display::DisplayOptions {
        title,
        vsync,
        frame_period: period,
        ..Default::default()
    };
    let viewer = py
        .detach(|| colcos_display::Viewer::open(opts, (width, height)))
        .map_err(|e| Kind::Display.err(e.to_string()))?;
    Ok(PyWindow {
        viewer: Mutex::new(Some(viewer)),
    })
}

#[cfg(not(feature = "display"))]
fn open(_: Python<'_>, _: u32, _: u32, _: String, _: f64, _: bool) -> PyResult<PyWindow> {
    Err(Kind::Display.err("this colcos was built without the `display` feature"))
}

#[cfg(feature = "display")]
fn show(v: &mut Viewer, rgba: Vec<u8>, size: (u32, u32)) -> bool {
    v.show(rgba, size)
}
#[cfg(feature = "display")]
fn close(v: Option<Viewer>) {
    if let Some(mut v) = v {
        v.close();
    }
}
#[cfg(feature = "display")]
fn is_open(v: &Viewer) -> bool {
    v.is_open()
}
#[cfg(feature = "display")]
fn presented(v: &Viewer) -> u64 {
    v.presented()
}

#[cfg(not(feature = "display"))]
fn show(_: &mut Viewer, _: Vec<u8>, _: (u32, u32)) -> bool {
    false
}
#[cfg(not(feature = "display"))]
fn close(_: Option<Viewer>) {}
#[cfg(not(feature = "display"))]
fn is_open(_: &Viewer) -> bool {
    false
}
#[cfg(not(feature = "display"))]
fn presented(_: &Viewer) -> u64 {
    0
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyWindow>()?;
    m.add("HAS_DISPLAY", cfg!(feature = "display"))?;
    m.add("HAS_GPU", cfg!(feature = "gpu"))?;
    Ok(())
}
