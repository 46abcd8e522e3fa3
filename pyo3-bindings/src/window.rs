//! `colcos._core.Window`: the display window of `render_mode="human"` (the `colcos-display` crate's
//! `Viewer`: a window on a display thread, fed images from Python, paced to the field's rate).
use crate::errors::DisplayError;
use numpy::{PyReadonlyArray3, PyUntypedArrayMethods};
use pyo3::prelude::*;
use std::sync::Mutex;

#[pyclass(module = "colcos._core", name = "Window")]
pub struct PyWindow {
    #[cfg(feature = "display")]
    viewer: Mutex<Option<colcos_display::Viewer>>,
    #[cfg(not(feature = "display"))]
    viewer: Mutex<Option<NoViewer>>,
}

/// Stands for the viewer in a build without the `display` feature (never made).
#[cfg(not(feature = "display"))]
struct NoViewer;

#[pymethods]
impl PyWindow {
    /// Opens a window for images of `width x height` pixels, shown at most `fps` times a second.
    /// Raises `colcos.DisplayError` where no window can be opened.
    #[new]
    #[pyo3(signature = (width, height, title="colcos", fps=50.0, vsync=true))]
    fn new(
        py: Python<'_>,
        width: u32,
        height: u32,
        title: &str,
        fps: f64,
        vsync: bool,
    ) -> PyResult<Self> {
        #[cfg(feature = "display")]
        {
            let period = if fps.is_finite() && fps > 0.0 {
                std::time::Duration::from_secs_f64(1.0 / fps)
            } else {
                std::time::Duration::ZERO
            };
            let opts = colcos_display::DisplayOptions {
                title: title.to_string(),
                vsync,
                frame_period: period,
                ..Default::default()
            };
            let viewer = py
                .detach(|| colcos_display::Viewer::open(opts, (width, height)))
                .map_err(|e| DisplayError::new_err(e.to_string()))?;
            Ok(PyWindow {
                viewer: Mutex::new(Some(viewer)),
            })
        }
        #[cfg(not(feature = "display"))]
        {
            let _ = (py, width, height, title, fps, vsync);
            Err(DisplayError::new_err(
                "this colcos was built without the `display` feature",
            ))
        }
    }

    /// Shows an `(H, W, 3)` or `(H, W, 4)` uint8 image (waiting, if need be, to keep to `fps`).
    /// Returns False once the window is closed (by the user or `close()`).
    fn show(&self, py: Python<'_>, image: PyReadonlyArray3<'_, u8>) -> PyResult<bool> {
        let shape = image.shape().to_vec();
        let (h, w, c) = (shape[0], shape[1], shape[2]);
        if c != 3 && c != 4 {
            return Err(DisplayError::new_err(format!(
                "image must be (H, W, 3) or (H, W, 4) uint8, got shape {shape:?}"
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
        let mut guard = self.viewer.lock().unwrap_or_else(|p| p.into_inner());
        let Some(v) = guard.as_mut() else {
            return Ok(false);
        };
        #[cfg(feature = "display")]
        {
            Ok(py.detach(|| v.show(rgba, (w as u32, h as u32))))
        }
        #[cfg(not(feature = "display"))]
        {
            let _ = (py, v, rgba);
            Ok(false)
        }
    }

    /// Closes the window (closing twice is harmless).
    fn close(&self, py: Python<'_>) {
        let v = self.viewer.lock().unwrap_or_else(|p| p.into_inner()).take();
        #[cfg(feature = "display")]
        if let Some(mut v) = v {
            py.detach(move || v.close());
        }
        #[cfg(not(feature = "display"))]
        let _ = (py, v);
    }

    /// Whether the window is still open.
    #[getter]
    fn is_open(&self) -> bool {
        #[cfg(feature = "display")]
        {
            self.viewer
                .lock()
                .unwrap_or_else(|p| p.into_inner())
                .as_ref()
                .is_some_and(|v| v.is_open())
        }
        #[cfg(not(feature = "display"))]
        false
    }

    /// Frames presented so far.
    #[getter]
    fn presented(&self) -> u64 {
        #[cfg(feature = "display")]
        {
            self.viewer
                .lock()
                .unwrap_or_else(|p| p.into_inner())
                .as_ref()
                .map_or(0, |v| v.presented())
        }
        #[cfg(not(feature = "display"))]
        0
    }
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyWindow>()?;
    m.add("HAS_DISPLAY", cfg!(feature = "display"))?;
    m.add("HAS_GPU", cfg!(feature = "gpu"))?;
    Ok(())
}
