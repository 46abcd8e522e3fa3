//! Static injection maps J from polylines and images.
use super::GridSpec;
use crate::error::Result;
use glam::Vec2;

/// `value` on every cell within `width / 2` of the polyline through `points`, 0 elsewhere.
pub fn polyline_map(_spec: &GridSpec, _points: &[Vec2], _width: f32, _value: f32) -> Vec<f32> {
    todo!()
}

/// A PNG resampled onto the grid (stretched over the arena, top row of the image at y = height):
/// `scale * level / 255` of the given channel (0 r, 1 g, 2 b; `None`: luma).
pub fn image_map(_spec: &GridSpec, _path: &std::path::Path, _channel: Option<usize>, _scale: f32) -> Result<Vec<f32>> {
    todo!()
}
