//! The screen, eq. (1): I(x, y, c) = clip(sum_j k_j Phi_j(x, y)) as 8-bit RGB at the panel's resolution.
use crate::error::{Result, SimError};
use crate::field::{FieldModel, Pheromone};
use glam::Vec2;
use rayon::prelude::*;
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
        ScreenSpec {
            resolution: [3840, 2160],
            size: [1.439, 0.809],
        }
    }
}

impl ScreenSpec {
    /// Size of one pixel, m: `(size.x / resolution.x, size.y / resolution.y)`.
    pub fn pixel_size(&self) -> Vec2 {
        Vec2::new(
            self.size[0] / self.resolution[0].max(1) as f32,
            self.size[1] / self.resolution[1].max(1) as f32,
        )
    }

    /// Centre of the pixel that shows point `p` (the screen is pixelated: a sensor sees pixels).
    /// Points outside the panel map to the nearest edge pixel.
    pub fn pixel_centre(&self, p: Vec2) -> Vec2 {
        let ps = self.pixel_size();
        let k = |v: f32, size: f32, n: u32| -> f32 {
            let n = n.max(1);
            let idx = if v.is_nan() {
                0.0
            } else {
                (v / size).floor().clamp(0.0, (n - 1) as f32)
            };
            (idx + 0.5) * size
        };
        Vec2::new(
            k(p.x, ps.x, self.resolution[0]),
            k(p.y, ps.y, self.resolution[1]),
        )
    }
}

/// Eq. (1) for one channel: `clip(round(level), 0, 255)` (NaN gives 0).
#[inline]
pub fn to_level(level: f32) -> u8 {
    // `as u8` saturates at 0 and 255 and maps NaN to 0.
    level.round() as u8
}

/// Eq. (1) at the pixel that shows `p`: 8-bit (r, g, b).
pub fn pixel_at(pheromones: &[Pheromone], screen: &ScreenSpec, p: Vec2) -> [u8; 3] {
    let c = screen.pixel_centre(p);
    let mut acc = [0f32; 3];
    for ph in pheromones {
        let v = ph.value_at(c);
        for (a, k) in acc.iter_mut().zip(ph.colour) {
            *a += k * v;
        }
    }
    acc.map(to_level)
}

/// The whole screen image, eq. (1), rendered at `width x height` pixels (the panel's own resolution or
/// a preview size), rows in parallel.
///
/// Pixel `(px, row)` samples the fields at the centre of that pixel of a `width x height` grid stretched
/// over the panel; row 0 is the top (`y = height`). Grid fields are resampled bilinearly (the same as
/// [`crate::field::GridField::value_at`], with the horizontal weights computed once per image).
pub fn render(
    pheromones: &[Pheromone],
    screen: &ScreenSpec,
    width: u32,
    height: u32,
) -> image::RgbImage {
    let (w, h) = (width as usize, height as usize);
    let mut img = image::RgbImage::new(width, height);
    if w == 0 || h == 0 {
        return img;
    }
    let px = screen.size[0] / w as f32;
    let py = screen.size[1] / h as f32;
    let xs: Vec<f32> = (0..w).map(|i| (i as f32 + 0.5) * px).collect();
    // Horizontal interpolation tables of the grid fields.
    let tables: Vec<Option<Vec<(u32, u32, f32)>>> = pheromones
        .iter()
        .map(|ph| match &ph.model {
            FieldModel::Grid(g) => {
                let s = g.spec();
                Some(
                    xs.iter()
                        .map(|&x| {
                            let (i0, i1, t) = crate::field::lerp_index(x / s.cell - 0.5, s.nx);
                            (i0 as u32, i1 as u32, t)
                        })
                        .collect(),
                )
            }
            FieldModel::Gaussian(_) => None,
        })
        .collect();
    let render_row = |(row, out): (usize, &mut [u8])| {
        let y = (h - 1 - row) as f32 * py + 0.5 * py;
        let mut acc = vec![[0f32; 3]; w];
        let mut vals = vec![0f32; w];
        for (ph, table) in pheromones.iter().zip(&tables) {
            match (&ph.model, table) {
                (FieldModel::Grid(g), Some(table)) => {
                    let s = g.spec();
                    let (j0, j1, ty) = crate::field::lerp_index(y / s.cell - 0.5, s.ny);
                    let v = g.values();
                    let lo = &v[j0 * s.nx..(j0 + 1) * s.nx];
                    let hi = &v[j1 * s.nx..(j1 + 1) * s.nx];
                    for (o, &(i0, i1, tx)) in vals.iter_mut().zip(table) {
                        let (i0, i1) = (i0 as usize, i1 as usize);
                        let a = lo[i0] + (lo[i1] - lo[i0]) * tx;
                        let b = hi[i0] + (hi[i1] - hi[i0]) * tx;
                        *o = a + (b - a) * ty;
                    }
                }
                _ => {
                    for (o, &x) in vals.iter_mut().zip(&xs) {
                        *o = ph.value_at(Vec2::new(x, y));
                    }
                }
            }
            for (a, &v) in acc.iter_mut().zip(&vals) {
                for (a, k) in a.iter_mut().zip(ph.colour) {
                    *a += k * v;
                }
            }
        }
        for (o, a) in out.chunks_exact_mut(3).zip(&acc) {
            o[0] = to_level(a[0]);
            o[1] = to_level(a[1]);
            o[2] = to_level(a[2]);
        }
    };
    let buf: &mut [u8] = &mut img;
    if w * h >= 1 << 16 {
        buf.par_chunks_mut(3 * w).enumerate().for_each(render_row);
    } else {
        buf.chunks_mut(3 * w).enumerate().for_each(render_row);
    }
    img
}

/// Writes an image as PNG.
pub fn save_png(img: &image::RgbImage, path: &std::path::Path) -> Result<()> {
    img.save_with_format(path, image::ImageFormat::Png)
        .map_err(|e| SimError::Image {
            path: path.display().to_string(),
            message: e.to_string(),
        })
}
