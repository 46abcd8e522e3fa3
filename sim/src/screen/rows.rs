//! One band of pixel rows: the grid rows its pixel rows read, interpolated at every pixel column
//! into a scratch buffer that stays in cache, then each pixel row blended from two of them, in
//! strips of columns (the strip's rows stay in L1), by the vector kernel ([`super::simd`]) or in
//! blocks of [`CHUNK`] pixels (any field model, any CPU).
use super::expand::ColumnTable;
#[cfg(target_arch = "x86_64")]
use super::simd;
use super::to_level;
use crate::field::FrozenSource;
use glam::Vec2;
use std::mem::MaybeUninit;

/// Pixels per inner block: the accumulators of a block stay in L1 and the loops have a fixed length.
pub(super) const CHUNK: usize = 64;

/// The vector instructions a [`super::ScreenRenderer`] may use. All give the same bytes; the choice is for
/// tests and comparisons.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Instructions {
    /// The widest this CPU has (AVX-512 with VBMI, else AVX2, else none).
    #[default]
    Best,
    /// At most AVX2.
    Avx2,
    /// None beyond the target's baseline.
    Portable,
}

/// One grid's cells and weights at the image's pixels, as [`crate::field::lerp_index`] gives them.
pub(super) struct GridLayout {
    /// The cells and weights of each pixel column.
    pub(super) cols: ColumnTable,
    /// `(j0, j1, ty)` of each pixel row, top row first.
    pub(super) rows: Vec<(u32, u32, f32)>,
}

/// Pixel columns per strip: a strip of the expanded rows a pixel row reads (two per grid) fits L1.
const STRIP: usize = 1024;

/// Where one pheromone's values come from in a frame.
pub(super) enum PlanSource<'a> {
    /// A grid and its tables. `bounded`: every value is finite and small enough that no
    /// interpolation overflows, so a zero colour weight adds exactly nothing and is skipped.
    Grid {
        grid: &'a GridLayout,
        /// The grid's values, rows of `nx`.
        values: &'a [f32],
        nx: usize,
        bounded: bool,
    },
    /// An empty grid: 0 everywhere, as [`crate::field::GridField::value_at`] gives.
    Zero,
    /// Gaussian sources frozen at the field's time, summed per pixel.
    Gaussian(&'a [FrozenSource]),
}

/// One frame's work: each pheromone's source and colour, and the pixel centres.
pub(super) struct Plan<'a> {
    pub(super) sources: Vec<(PlanSource<'a>, [f32; 3])>,
    pub(super) width: usize,
    pub(super) stride: usize,
    pub(super) xs: &'a [f32],
    pub(super) ys: &'a [f32],
    /// Vector instructions allowed (the grid rows' expansion).
    pub(super) vector: bool,
    /// The vector kernel and what it adds up, when the CPU has one and every pheromone is on a
    /// (non-empty) grid.
    #[cfg(target_arch = "x86_64")]
    pub(super) kernel: Option<(simd::Level, simd::Products)>,
}

impl<'a> Plan<'a> {
    pub(super) fn new(
        sources: Vec<(PlanSource<'a>, [f32; 3])>,
        width: usize,
        stride: usize,
        xs: &'a [f32],
        ys: &'a [f32],
        instructions: Instructions,
    ) -> Plan<'a> {
        Plan {
            vector: instructions != Instructions::Portable,
            #[cfg(target_arch = "x86_64")]
            kernel: kernel(&sources, instructions),
            sources,
            width,
            stride,
            xs,
            ys,
        }
    }
}

/// The vector kernel for `sources`, if it takes them all.
#[cfg(target_arch = "x86_64")]
fn kernel(
    sources: &[(PlanSource, [f32; 3])],
    instructions: Instructions,
) -> Option<(simd::Level, simd::Products)> {
    if sources.len() > simd::MAX_TERMS {
        return None;
    }
    let mut products = simd::Products::default();
    for (t, (source, colour)) in sources.iter().enumerate() {
        let PlanSource::Grid { bounded, .. } = source else {
            return None;
        };
        for (c, &k) in colour.iter().enumerate() {
            if k != 0.0 || !bounded {
                products.push(c, t, k);
            }
        }
    }
    let level = match (instructions, simd::level()?) {
        (Instructions::Portable, _) => return None,
        (Instructions::Avx2, _) => simd::Level::Avx2,
        (Instructions::Best, level) => level,
    };
    Some((level, products))
}

/// True when every value is finite and at most a quarter of `f32::MAX` in size: then interpolations
/// between them are finite and `0 * v` is a zero that changes no sum.
pub(super) fn bounded(values: &[f32]) -> bool {
    let mut max = 0f32;
    for c in values.chunks(256) {
        // NaN fails every comparison: `m` stays infinite for a block holding one.
        let m = c.iter().fold(0f32, |m, v| {
            let a = v.abs();
            if a <= m {
                m
            } else if a <= f32::MAX {
                a
            } else {
                f32::INFINITY
            }
        });
        max = max.max(m);
    }
    max <= f32::MAX / 4.0
}

/// A band's expanded grid rows, kept between bands of one thread.
#[derive(Default)]
pub(super) struct BandScratch {
    rows: Vec<f32>,
    /// Per source: where its rows start in `rows`, and the grid row of the first.
    spans: Vec<(usize, u32)>,
    needed: Vec<bool>,
    /// A row of zeros, what a channel that nothing adds to reads.
    zeros: Vec<f32>,
}

impl BandScratch {
    /// The expanded grid row `j` of source `s`.
    #[inline]
    fn line(&self, stride: usize, s: usize, j: u32) -> &[f32] {
        let (at, first) = self.spans[s];
        &self.rows[at + (j - first) as usize * stride..][..stride]
    }
}

/// Renders pixel rows `first..` into `out` (whole rows of RGB bytes, all written).
pub(super) fn render_band(
    plan: &Plan,
    first: usize,
    out: &mut [MaybeUninit<u8>],
    scratch: &mut BandScratch,
) {
    let line = 3 * plan.width;
    let rows = first..first + out.len() / line;
    expand_band(plan, rows.clone(), scratch);
    for start in (0..plan.width).step_by(STRIP) {
        let cols = start..(start + STRIP).min(plan.width);
        for (row, out) in rows.clone().zip(out.chunks_exact_mut(line)) {
            if row == first || !plan.same_as_above(row) {
                render_row(
                    plan,
                    scratch,
                    row,
                    cols.clone(),
                    &mut out[3 * cols.start..3 * cols.end],
                );
            }
        }
    }
    for k in 1..rows.len() {
        if plan.same_as_above(first + k) {
            let (above, rest) = out.split_at_mut(k * line);
            rest[..line].copy_from_slice(&above[(k - 1) * line..]);
        }
    }
}

/// Interpolates the grid rows that the pixel rows `rows` read, each at every pixel column.
fn expand_band(plan: &Plan, rows: std::ops::Range<usize>, scratch: &mut BandScratch) {
    let BandScratch {
        rows: buf,
        spans,
        needed,
        zeros,
    } = scratch;
    zeros.resize(plan.stride, 0.0);
    spans.clear();
    let mut len = 0;
    for (source, _) in &plan.sources {
        let mut span = (len, 0);
        if let PlanSource::Grid { grid, .. } = source {
            let band = &grid.rows[rows.clone()];
            let lo = band.iter().map(|r| r.0).min().unwrap_or(0);
            let hi = band.iter().map(|r| r.1).max().unwrap_or(0);
            span = (len, lo);
            len += (hi - lo + 1) as usize * plan.stride;
        }
        spans.push(span);
    }
    buf.resize(len, 0.0);
    for ((source, _), &(at, lo)) in plan.sources.iter().zip(spans.iter()) {
        if let PlanSource::Grid {
            grid, values, nx, ..
        } = source
        {
            needed.clear();
            for &(j0, j1, _) in &grid.rows[rows.clone()] {
                for j in [j0, j1] {
                    let k = (j - lo) as usize;
                    if needed.len() <= k {
                        needed.resize(k + 1, false);
                    }
                    needed[k] = true;
                }
            }
            for (k, _) in needed.iter().enumerate().filter(|(_, n)| **n) {
                let j = lo as usize + k;
                let out = &mut buf[at + k * plan.stride..][..plan.stride];
                grid.cols
                    .expand(&values[j * nx..(j + 1) * nx], out, plan.vector);
            }
        }
    }
}

impl Plan<'_> {
    /// Row `row` reads the same grid rows with the same weights as the row above (where the image
    /// extends past the outermost cell centres), and no Gaussian field: its pixels are a copy.
    #[inline]
    fn same_as_above(&self, row: usize) -> bool {
        row > 0
            && self.sources.iter().all(|(source, _)| match source {
                PlanSource::Grid { grid, .. } => {
                    let ((a0, a1, at), (b0, b1, bt)) = (grid.rows[row - 1], grid.rows[row]);
                    a0 == b0 && a1 == b1 && at.to_bits() == bt.to_bits()
                }
                PlanSource::Zero => true,
                PlanSource::Gaussian(_) => false,
            })
    }
}

/// Columns `cols` (starting on a whole block) of one pixel row: grids only through the vector
/// kernel where the CPU has one, otherwise in blocks.
fn render_row(
    plan: &Plan,
    band: &BandScratch,
    row: usize,
    cols: std::ops::Range<usize>,
    out: &mut [MaybeUninit<u8>],
) {
    #[cfg(target_arch = "x86_64")]
    if let Some((level, products)) = &plan.kernel {
        let mut terms = [simd::Term::NONE; simd::MAX_TERMS];
        for (s, ((source, _), term)) in plan.sources.iter().zip(&mut terms).enumerate() {
            if let PlanSource::Grid { grid, .. } = source {
                let (j0, j1, ty) = grid.rows[row];
                *term = simd::Term {
                    lo: &band.line(plan.stride, s, j0)[cols.start..],
                    hi: &band.line(plan.stride, s, j1)[cols.start..],
                    ty,
                };
            }
        }
        let n = plan.sources.len();
        if let Some(single) = products.single() {
            let zeros = simd::Term {
                lo: &band.zeros,
                hi: &band.zeros,
                ty: 0.0,
            };
            let channels = single.map(|p| match p {
                Some((t, k)) => simd::Channel {
                    term: terms[t as usize],
                    k,
                },
                None => simd::Channel {
                    term: zeros,
                    k: 0.0,
                },
            });
            return simd::channel_row(*level, &channels, out);
        }
        return simd::grid_row(*level, &terms[..n], products, out);
    }
    render_row_blocks(plan, band, row, cols, out)
}

/// Columns `cols` of one pixel row in blocks of [`CHUNK`] pixels, any field model.
fn render_row_blocks(
    plan: &Plan,
    band: &BandScratch,
    row: usize,
    cols: std::ops::Range<usize>,
    out: &mut [MaybeUninit<u8>],
) {
    let y = plan.ys[row];
    for (c, block) in out.chunks_mut(3 * CHUNK).enumerate() {
        let start = cols.start + c * CHUNK;
        let n = block.len() / 3;
        let mut acc = [[0f32; CHUNK]; 3];
        let mut vals = [0f32; CHUNK];
        for (s, (source, colour)) in plan.sources.iter().enumerate() {
            let mut skip_zero = true;
            match source {
                PlanSource::Grid { grid, bounded, .. } => {
                    let (j0, j1, ty) = grid.rows[row];
                    let a = &band.line(plan.stride, s, j0)[start..][..CHUNK];
                    let b = &band.line(plan.stride, s, j1)[start..][..CHUNK];
                    for ((v, &a), &b) in vals.iter_mut().zip(a).zip(b) {
                        *v = a + (b - a) * ty;
                    }
                    skip_zero = *bounded;
                }
                PlanSource::Zero => vals = [0.0; CHUNK],
                PlanSource::Gaussian(frozen) => {
                    for (v, &x) in vals[..n].iter_mut().zip(&plan.xs[start..]) {
                        let p = Vec2::new(x, y);
                        *v = frozen.iter().map(|s| s.value_at(p)).sum();
                    }
                    skip_zero = false;
                }
            }
            for (a, &k) in acc.iter_mut().zip(colour) {
                if k == 0.0 && skip_zero {
                    continue;
                }
                for (a, &v) in a.iter_mut().zip(&vals) {
                    *a += k * v;
                }
            }
        }
        for (k, o) in block.chunks_exact_mut(3).enumerate() {
            o[0].write(to_level(acc[0][k]));
            o[1].write(to_level(acc[1][k]));
            o[2].write(to_level(acc[2][k]));
        }
    }
}
