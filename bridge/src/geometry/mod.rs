//! Plane geometry under everything else: projective maps of the plane ([`Homography`], fitted by DLT
//! and RANSAC) and the calibrated map from tracker coordinates to the simulator's frame
//! ([`ScreenMap`]). No I/O and no rig: the wire formats, the calibration and the twin's camera build
//! on it.
mod homography;
mod screen_map;

pub use homography::Homography;
pub(crate) use homography::{fit_dlt, fit_ransac, residual};
pub use screen_map::ScreenMap;
pub(crate) use screen_map::wrap_pi;
