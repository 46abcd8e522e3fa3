//! Static injection maps J from polylines and images.
use super::GridSpec;
use crate::channel::Channel;
use crate::error::{Result, SimError};
use glam::Vec2;

/// `value` on every cell within `width / 2` of the polyline through `points`, 0 elsewhere.
/// Overlapping segments do not add up (the map takes the maximum). A single point gives a disc.
pub fn polyline_map(spec: &GridSpec, points: &[Vec2], width: f32, value: f32) -> Vec<f32> {
    let mut map = vec![0.0f32; spec.len()];
    let half = 0.5 * width.max(0.0);
    let segments: Vec<(Vec2, Vec2)> = match points {
        [] => Vec::new(),
        [p] => vec![(*p, *p)],
        _ => points.windows(2).map(|w| (w[0], w[1])).collect(),
    };
    for (a, b) in segments {
        let ((i0, i1), (j0, j1)) = spec.segment_cells(a, b, half);
        let ab = b - a;
        let len2 = ab.length_squared();
        for j in j0..j1 {
            for i in i0..i1 {
                let p = spec.cell_centre(i, j);
                let t = if len2 > 0.0 {
                    ((p - a).dot(ab) / len2).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                if (p - (a + ab * t)).length() <= half {
                    let v = &mut map[j * spec.nx + i];
                    *v = v.max(value);
                }
            }
        }
    }
    map
}

/// A PNG resampled onto the grid (stretched over the arena, top row of the image at y = height):
/// `scale * level / 255` of the given colour channel (`None`: luma).
///
/// Resampling is bilinear between pixel centres (clamped at the edges); luma is Rec. 601
/// (`0.299 r + 0.587 g + 0.114 b`).
pub fn image_map(
    spec: &GridSpec,
    path: &std::path::Path,
    channel: Option<Channel>,
    scale: f32,
) -> Result<Vec<f32>> {
    let err = |message: String| SimError::Image {
        path: path.display().to_string(),
        message,
    };
    let img = image::open(path).map_err(|e| err(e.to_string()))?.to_rgb8();
    let (w, h) = (img.width() as usize, img.height() as usize);
    if w == 0 || h == 0 {
        return Err(err("the image is empty".into()));
    }
    let level = |x: usize, y: usize| -> f32 {
        let p = img.get_pixel(x as u32, y as u32).0;
        match channel {
            Some(c) => p[c.index()] as f32,
            None => 0.299 * p[0] as f32 + 0.587 * p[1] as f32 + 0.114 * p[2] as f32,
        }
    };
    let mut map = vec![0.0f32; spec.len()];
    let (nx, ny) = (spec.nx, spec.ny);
    for j in 0..ny {
        // Fraction of the height from the top, then image row coordinate (pixel centres at k + 0.5).
        let v = (1.0 - (j as f32 + 0.5) / ny as f32) * h as f32 - 0.5;
        let (y0, y1, ty) = super::grid::lerp_index(v, h);
        for i in 0..nx {
            let u = (i as f32 + 0.5) / nx as f32 * w as f32 - 0.5;
            let (x0, x1, tx) = super::grid::lerp_index(u, w);
            let top = level(x0, y0) + (level(x1, y0) - level(x0, y0)) * tx;
            let bot = level(x0, y1) + (level(x1, y1) - level(x0, y1)) * tx;
            let l = top + (bot - top) * ty;
            map[j * nx + i] = scale * l / 255.0;
        }
    }
    Ok(map)
}
