//! The screen, eq. (1): I(x, y, c) = clip(sum_j k_j Phi_j(x, y)) as 8-bit RGB at the panel's resolution.
use crate::field::Pheromone;
use glam::Vec2;
use serde::{Deserialize, Serialize};

/// The display panel: resolution in pixels and physical size in metres. Pixel row 0 is at the top
/// (`y = height`), as in images.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ScreenSpec {
    pub resolution: [u32; 2],
    /// m.
    pub size: [f32; 2],
}

impl Default for ScreenSpec {
    /// The paper's 65-inch 4K panel.
    fn default() -> Self {
        ScreenSpec { resolution: [3840, 2160], size: [1.439, 0.809] }
    }
}

impl ScreenSpec {
    /// Centre of the pixel that shows point `p` (the screen is pixelated: a sensor sees pixels).
    pub fn pixel_centre(&self, _p: Vec2) -> Vec2 {
        todo!()
    }
}

/// Eq. (1) at the pixel that shows `p`: 8-bit (r, g, b).
pub fn pixel_at(_pheromones: &[Pheromone], _screen: &ScreenSpec, _p: Vec2) -> [u8; 3] {
    todo!()
}

/// The whole screen image, eq. (1), rendered at `width x height` pixels (the panel's own resolution or
/// a preview size), rows in parallel.
pub fn render(_pheromones: &[Pheromone], _screen: &ScreenSpec, _width: u32, _height: u32) -> image::RgbImage {
    todo!()
}
