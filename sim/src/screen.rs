//! The screen, eq. (1): I(x, y, c) = clip(sum_j k_j Phi_j(x, y)) as 8-bit RGB at the panel's resolution.
use crate::error::{Result, SimError};
use crate::field::{FieldModel, FrozenSources, GridSampler, NearbyPoints, Pheromone};
use glam::Vec2;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// The display panel: resolution in pixels and physical size in metres. Pixel row 0 is at the top
/// (`y = height`), as in images.
/// A `[screen]` table that gives only one key takes the default (the paper's panel) for the other.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
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
        self.pixel_centre_with(self.pixel_size(), p)
    }

    /// [`ScreenSpec::pixel_centre`] with the pixel size computed once by the caller.
    #[inline]
    pub fn pixel_centre_with(&self, ps: Vec2, p: Vec2) -> Vec2 {
        Vec2::new(
            pixel_centre_coord(p.x, ps.x, self.resolution[0]),
            pixel_centre_coord(p.y, ps.y, self.resolution[1]),
        )
    }
}

/// One coordinate of [`ScreenSpec::pixel_centre`]: the centre of pixel `clamp(floor(v / size), 0, n - 1)`
/// of `n` pixels of `size`. Branch-free so that loops over many points vectorise: truncation is floor
/// for `v >= 0`, and negative (or NaN) `v` clamps to pixel 0 anyway (no libm `floorf` call on baseline
/// x86-64); clamping to `n - 1` before truncating gives the same pixel as after, `n - 1` being an
/// integer.
#[inline(always)]
pub fn pixel_centre_coord(v: f32, size: f32, n: u32) -> f32 {
    // (Capped far beyond any panel, validated scenarios allow 65,536 pixels, so the truncation below
    // stays within i32.)
    let last = (n.max(1) - 1).min(1 << 30) as f32;
    let f = v / size;
    let f = if f > 0.0 { f.min(last) } else { 0.0 };
    // SAFETY: `f` is in [0, n - 1] (NaN went to 0 above), so the truncation is in range; the plain
    // conversion (not the saturating `as`) is what vectorises.
    (unsafe { f.to_int_unchecked::<i32>() } as f32 + 0.5) * size
}

/// Eq. (1) for one channel: `clip(round(level), 0, 255)`, rounding half away from zero (NaN gives 0).
/// Without a libm call and branch-free, so that loops over many pixels vectorise: clamp first, then
/// truncate and look at the fraction (both exact in f32).
#[inline(always)]
pub fn to_level(level: f32) -> u8 {
    to_level_u32(level) as u8
}

/// [`to_level`] as a `u32` (0..=255).
#[inline(always)]
pub fn to_level_u32(level: f32) -> u32 {
    let c = if level > 0.0 { level.min(255.0) } else { 0.0 };
    // SAFETY: `c` is in [0, 255] (NaN went to 0 above), so the truncation is in range; the plain
    // conversion (not the saturating `as`) is what vectorises.
    let t = unsafe { c.to_int_unchecked::<i32>() };
    (t + i32::from(c - t as f32 >= 0.5)) as u32
}

/// Eq. (1) at the pixel that shows `p`: 8-bit (r, g, b).
pub fn pixel_at(pheromones: &[Pheromone], screen: &ScreenSpec, p: Vec2) -> [u8; 3] {
    pixels_at(pheromones, screen, &[p])[0]
}

/// Eq. (1) at the pixels that show each of `points` (a sensor's footprint). Same values as
/// [`pixel_at`] per point; see [`pixels_at_frozen`].
pub fn pixels_at<const N: usize>(
    pheromones: &[Pheromone],
    screen: &ScreenSpec,
    points: &[Vec2; N],
) -> [[u8; 3]; N] {
    pixels_at_frozen(pheromones, &FrozenSources::new(pheromones), screen, points)
}

/// [`pixels_at`] with the Gaussian sources already frozen at the fields' time (`frozen` must come from
/// these `pheromones` as they are now).
pub fn pixels_at_frozen<const N: usize>(
    pheromones: &[Pheromone],
    frozen: &FrozenSources,
    screen: &ScreenSpec,
    points: &[Vec2; N],
) -> [[u8; 3]; N] {
    let levels = levels_at(pheromones, frozen, screen, points, N);
    let mut out = [[0u8; 3]; N];
    for (k, o) in out.iter_mut().enumerate() {
        *o = [levels[0][k] as u8, levels[1][k] as u8, levels[2][k] as u8];
    }
    out
}

/// Eq. (1) at the pixels that show each of `points`: 8-bit levels (0..=255), `[channel][point]`. The
/// points come in groups of `group` consecutive points close together (sensor footprints): a group
/// shares one `exp` per Gaussian source. The pixel
/// centres and the grids' interpolation weights are computed once per point and shared by every field
/// on the same grid; the arithmetic runs over arrays of points (structure of arrays) so that it
/// vectorises.
pub fn levels_at<const N: usize>(
    pheromones: &[Pheromone],
    frozen: &FrozenSources,
    screen: &ScreenSpec,
    points: &[Vec2; N],
    group: usize,
) -> [[u32; N]; 3] {
    #[cfg(target_arch = "x86_64")]
    if std::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU has AVX2.
        return unsafe { levels_at_avx2(pheromones, frozen, screen, points, group) };
    }
    levels_at_portable(pheromones, frozen, screen, points, group)
}

/// [`levels_at`] compiled for AVX2: the same operations in wider registers (twice the f64 lanes of
/// baseline x86-64's SSE2 for the Gaussian exponents). Rust never fuses a multiply and an add on its
/// own, so the results are bit-identical to [`levels_at_portable`] (tested).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn levels_at_avx2<const N: usize>(
    pheromones: &[Pheromone],
    frozen: &FrozenSources,
    screen: &ScreenSpec,
    points: &[Vec2; N],
    group: usize,
) -> [[u32; N]; 3] {
    levels_at_portable(pheromones, frozen, screen, points, group)
}

/// [`levels_at`] for any x86-64 (or other) processor.
#[inline(always)]
pub fn levels_at_portable<const N: usize>(
    pheromones: &[Pheromone],
    frozen: &FrozenSources,
    screen: &ScreenSpec,
    points: &[Vec2; N],
    group: usize,
) -> [[u32; N]; 3] {
    let group = group.clamp(1, N.max(1));
    let pixel = screen.pixel_size();
    let [nx, ny] = screen.resolution;
    let (mut xs, mut ys) = ([0f32; N], [0f32; N]);
    for ((x, y), p) in xs.iter_mut().zip(&mut ys).zip(points) {
        *x = pixel_centre_coord(p.x, pixel.x, nx);
        *y = pixel_centre_coord(p.y, pixel.y, ny);
    }
    // One group (a robot's footprints, the usual call): its offsets computed once for every source.
    let near = (group == N && !frozen.is_empty()).then(|| NearbyPoints::<N>::new(&xs, &ys));
    let mut acc = [[0f32; N]; 3];
    let mut grid = GridSampler::<N>::new();
    let mut values = [0f32; N];
    for (index, ph) in pheromones.iter().enumerate() {
        match &ph.model {
            FieldModel::Grid(g) => {
                if g.spec().is_empty() {
                    continue;
                }
                grid.values(g, &xs, &ys, &mut values);
            }
            FieldModel::Gaussian(_) => {
                values.fill(0.0);
                for source in frozen.of(index) {
                    match &near {
                        Some(near) => source.add_values_near(near, &xs, &ys, &mut values),
                        None => source.add_values_soa(&xs, &ys, group, &mut values),
                    }
                }
            }
        }
        for (a, &k) in acc.iter_mut().zip(&ph.colour) {
            for (a, &v) in a.iter_mut().zip(&values) {
                *a += k * v;
            }
        }
    }
    // 32-bit levels: with byte-sized results this loop did not vectorise.
    let mut out = [[0u32; N]; 3];
    for (o, a) in out.iter_mut().zip(&acc) {
        for (o, &a) in o.iter_mut().zip(a) {
            *o = to_level_u32(a);
        }
    }
    out
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
