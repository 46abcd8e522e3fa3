//! The screen, eq. (1): I(x, y, c) = clip(sum_j k_j Phi_j(x, y)) as 8-bit RGB at the panel's resolution.
use crate::error::{Result, SimError};
use crate::field::{FieldModel, FrozenSources, GridSampler, NearbyPoints, Pheromone};
use glam::Vec2;
use serde::{Deserialize, Serialize};

mod expand;
mod footprint;
mod render;
mod rows;
mod simd;
#[cfg(target_arch = "x86_64")]
pub use footprint::footprint_levels_avx2;
pub use footprint::{
    FootprintLevels, FootprintSamples, LANES as FOOTPRINT_LANES, SAMPLES as FOOTPRINT_SAMPLES,
    footprint_levels,
};
pub use render::ScreenRenderer;
pub use rows::Instructions;

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
        ScreenSpec::new([3840, 2160], [1.439, 0.809])
    }
}

impl ScreenSpec {
    /// A panel of `resolution` pixels and `size` metres.
    pub const fn new(resolution: [u32; 2], size: [f32; 2]) -> Self {
        ScreenSpec { resolution, size }
    }

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
    let frozen = FrozenSources::new(pheromones);
    let fields = ScreenFields {
        pheromones,
        frozen: &frozen,
        screen,
    };
    pixels_at_frozen(&fields, points)
}

/// What eq. (1) sums on a panel at one time: the pheromones, with their Gaussian sources already
/// frozen at the fields' time (`frozen` must come from these `pheromones` as they are now).
#[derive(Clone, Copy)]
pub struct ScreenFields<'a> {
    pub pheromones: &'a [Pheromone],
    pub frozen: &'a FrozenSources,
    pub screen: &'a ScreenSpec,
}

/// [`pixels_at`] with the Gaussian sources already frozen.
pub fn pixels_at_frozen<const N: usize>(fields: &ScreenFields, points: &[Vec2; N]) -> [[u8; 3]; N] {
    let levels = levels_at(fields, points, N);
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
    fields: &ScreenFields,
    points: &[Vec2; N],
    group: usize,
) -> [[u32; N]; 3] {
    #[cfg(target_arch = "x86_64")]
    if std::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU has AVX2.
        return unsafe { levels_at_avx2(fields, points, group) };
    }
    levels_at_portable(fields, points, group)
}

/// [`levels_at`] compiled for AVX2: the same operations in wider registers (twice the f64 lanes of
/// baseline x86-64's SSE2 for the Gaussian exponents). Rust never fuses a multiply and an add on its
/// own, so the results are bit-identical to [`levels_at_portable`] (tested).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn levels_at_avx2<const N: usize>(
    fields: &ScreenFields,
    points: &[Vec2; N],
    group: usize,
) -> [[u32; N]; 3] {
    levels_at_portable(fields, points, group)
}

/// [`levels_at`] for any x86-64 (or other) processor.
#[inline(always)]
pub fn levels_at_portable<const N: usize>(
    fields: &ScreenFields,
    points: &[Vec2; N],
    group: usize,
) -> [[u32; N]; 3] {
    let ScreenFields {
        pheromones,
        frozen,
        screen,
    } = *fields;
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
/// [`crate::field::GridField::value_at`], bit for bit), Gaussian fields exactly per pixel. See
/// [`render_into`] to reuse the image, and [`ScreenRenderer`] for how it is fast.
pub fn render(
    pheromones: &[Pheromone],
    screen: &ScreenSpec,
    width: u32,
    height: u32,
) -> image::RgbImage {
    with_renderer(|r| r.render(pheromones, screen, width, height))
}

/// [`render`] into an existing image, at its size: no new image (at 4K a fresh one costs more than
/// drawing it, in page faults), and the calling thread's [`ScreenRenderer`] keeps its tables.
pub fn render_into(pheromones: &[Pheromone], screen: &ScreenSpec, img: &mut image::RgbImage) {
    with_renderer(|r| r.render_into(pheromones, screen, img))
}

/// Runs `f` with this thread's kept renderer.
fn with_renderer<T>(f: impl FnOnce(&mut ScreenRenderer) -> T) -> T {
    thread_local! {
        static RENDERER: std::cell::RefCell<ScreenRenderer> = Default::default();
    }
    RENDERER.with(|r| match r.try_borrow_mut() {
        Ok(mut r) => f(&mut r),
        // Drawing again on this thread while it draws (a rayon task stolen during the first).
        Err(_) => f(&mut ScreenRenderer::new()),
    })
}

/// Writes an image as PNG.
pub fn save_png(img: &image::RgbImage, path: &std::path::Path) -> Result<()> {
    img.save_with_format(path, image::ImageFormat::Png)
        .map_err(|e| SimError::Image {
            path: path.display().to_string(),
            message: e.to_string(),
        })
}
