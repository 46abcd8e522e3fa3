//! The whole screen image of eq. (1), fast: a [`ScreenRenderer`] keeps, per image size, each grid's
//! interpolation cells and weights for every pixel column and row; per frame, bands of pixel rows
//! run in parallel, each interpolating the grid rows it reads horizontally once, at every pixel
//! column, and blending each of its pixel rows from two of those, in vector registers. The
//! arithmetic is [`crate::field::GridField::value_at`]'s (horizontal first, then vertical, unfused)
//! and eq. (1)'s, so the image is bit for bit the per-pixel one (Gaussian fields are evaluated per
//! pixel, their sources frozen once per frame). 3840x2160 with three grids: ~2 ms on two cores.
use super::ScreenSpec;
use super::expand::ColumnTable;
use super::rows::{self, BandScratch, CHUNK, GridLayout, Instructions, Plan, PlanSource};
use crate::field::{FieldModel, FrozenSources, GridSpec, Pheromone, lerp_index};
use rayon::prelude::*;
use std::mem::MaybeUninit;

/// Pixel rows per parallel task: each expands the grid rows its pixel rows read (about 4 of 5 mm
/// cells at 4K, so a row is expanded 1.3 times on average), and they stay in cache.
const BAND_ROWS: usize = 48;
/// Images with fewer pixels than this render on the calling thread.
const PARALLEL_MIN_PIXELS: usize = 1 << 16;

/// Renders eq. (1) into images, keeping its lookup tables (per image size and grid geometry) between
/// calls; a band's scratch rows (a few hundred KB at 4K) are made per frame.
#[derive(Default)]
pub struct ScreenRenderer {
    layout: Option<Layout>,
    frozen: FrozenSources,
    instructions: Instructions,
}

/// What the tables were made for.
#[derive(Clone, Debug, PartialEq)]
struct LayoutKey {
    width: u32,
    height: u32,
    size: [u32; 2],
    specs: Vec<Option<GridSpec>>,
}

struct Layout {
    key: LayoutKey,
    /// Row length of the expanded grid rows: the width rounded up to whole blocks.
    stride: usize,
    /// Pixel centres, m (padded to `stride`).
    xs: Vec<f32>,
    /// Pixel row centres, m, top row first.
    ys: Vec<f32>,
    grids: Vec<Option<GridLayout>>,
}

impl Layout {
    fn new(key: LayoutKey, screen_size: [f32; 2]) -> Layout {
        let (w, h) = (key.width as usize, key.height as usize);
        let stride = w.div_ceil(CHUNK) * CHUNK;
        let px = screen_size[0] / w as f32;
        let py = screen_size[1] / h as f32;
        let mut xs: Vec<f32> = (0..w).map(|i| (i as f32 + 0.5) * px).collect();
        xs.resize(stride, xs.last().copied().unwrap_or(0.0));
        let ys: Vec<f32> = (0..h)
            .map(|row| (h - 1 - row) as f32 * py + 0.5 * py)
            .collect();
        let grids = key
            .specs
            .iter()
            .map(|spec| {
                spec.map(|s| {
                    let lerp = |v: f32, n: usize| {
                        let (a, b, t) = lerp_index(v / s.cell - 0.5, n);
                        (a as u32, b as u32, t)
                    };
                    let cols = ColumnTable::new(&xs[..w], s.nx, s.cell);
                    let rows = ys.iter().map(|&y| lerp(y, s.ny)).collect();
                    GridLayout { cols, rows }
                })
            })
            .collect();
        Layout {
            key,
            stride,
            xs,
            ys,
            grids,
        }
    }
}

impl ScreenRenderer {
    pub fn new() -> ScreenRenderer {
        ScreenRenderer::default()
    }

    /// A renderer that uses at most `instructions`.
    pub fn with_instructions(instructions: Instructions) -> ScreenRenderer {
        ScreenRenderer {
            instructions,
            ..ScreenRenderer::default()
        }
    }

    /// Eq. (1) at `img`'s size (the panel's resolution or a preview size), into `img`: the same
    /// bytes as [`super::render`].
    pub fn render_into(
        &mut self,
        pheromones: &[Pheromone],
        screen: &ScreenSpec,
        img: &mut image::RgbImage,
    ) {
        let (width, height) = img.dimensions();
        let buf: &mut [u8] = img;
        // SAFETY: the renderer only writes initialised bytes through the view.
        let buf = unsafe { &mut *(buf as *mut [u8] as *mut [MaybeUninit<u8>]) };
        self.render_uninit(pheromones, screen, width, height, buf);
    }

    /// [`ScreenRenderer::render_into`] into a new image, whose bytes are written once.
    pub fn render(
        &mut self,
        pheromones: &[Pheromone],
        screen: &ScreenSpec,
        width: u32,
        height: u32,
    ) -> image::RgbImage {
        let len = (width as usize)
            .checked_mul(height as usize)
            .and_then(|n| n.checked_mul(3))
            .unwrap_or_else(|| panic!("a {width}x{height} image does not fit in memory"));
        let mut buf = Vec::with_capacity(len);
        self.render_uninit(
            pheromones,
            screen,
            width,
            height,
            &mut buf.spare_capacity_mut()[..len],
        );
        // SAFETY: `render_uninit` wrote every byte of the image.
        unsafe { buf.set_len(len) };
        image::RgbImage::from_raw(width, height, buf).expect("3 bytes a pixel")
    }

    /// Writes every byte of the `width x height` image `buf`.
    fn render_uninit(
        &mut self,
        pheromones: &[Pheromone],
        screen: &ScreenSpec,
        width: u32,
        height: u32,
        buf: &mut [MaybeUninit<u8>],
    ) {
        let (w, h) = (width as usize, height as usize);
        assert_eq!(buf.len(), 3 * w * h, "3 bytes a pixel");
        if w == 0 || h == 0 {
            return;
        }
        let key = LayoutKey {
            width,
            height,
            size: screen.size.map(f32::to_bits),
            specs: pheromones
                .iter()
                .map(|ph| match &ph.model {
                    FieldModel::Grid(g) if !g.spec().is_empty() => Some(*g.spec()),
                    _ => None,
                })
                .collect(),
        };
        if self.layout.as_ref().is_none_or(|l| l.key != key) {
            self.layout = Some(Layout::new(key, screen.size));
        }
        let layout = self.layout.as_ref().expect("layout made above");
        if pheromones
            .iter()
            .any(|ph| matches!(ph.model, FieldModel::Gaussian(_)))
        {
            self.frozen.refresh(pheromones);
        }
        let sources: Vec<_> = pheromones
            .iter()
            .zip(&layout.grids)
            .enumerate()
            .map(|(index, (ph, grid))| {
                let source = match (&ph.model, grid) {
                    (FieldModel::Grid(g), Some(grid)) => {
                        assert_eq!(g.values().len(), g.spec().len(), "one value per cell");
                        PlanSource::Grid {
                            grid,
                            values: g.values(),
                            nx: g.spec().nx,
                            bounded: rows::bounded(g.values()),
                        }
                    }
                    (FieldModel::Grid(_), None) => PlanSource::Zero,
                    (FieldModel::Gaussian(_), _) => PlanSource::Gaussian(self.frozen.of(index)),
                };
                (source, ph.colour)
            })
            .collect();
        let plan = Plan::new(
            sources,
            w,
            layout.stride,
            &layout.xs,
            &layout.ys,
            self.instructions,
        );

        let band = 3 * w * BAND_ROWS;
        if w * h >= PARALLEL_MIN_PIXELS {
            buf.par_chunks_mut(band)
                .enumerate()
                .for_each_init(BandScratch::default, |scratch, (b, out)| {
                    rows::render_band(&plan, b * BAND_ROWS, out, scratch)
                });
        } else {
            let mut scratch = BandScratch::default();
            for (b, out) in buf.chunks_mut(band).enumerate() {
                rows::render_band(&plan, b * BAND_ROWS, out, &mut scratch);
            }
        }
    }
}
