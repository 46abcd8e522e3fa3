//! A grid row interpolated at every pixel column, the first (horizontal) step of the bilinear
//! interpolation: `out[px] = lo[i0] + (lo[i1] - lo[i0]) tx`, with `(i0, i1, tx)` of each column
//! computed once per image size. Where the pixels are finer than the cells, each run of eight
//! columns reads at most eight neighbouring cells: one load and two in-register permutes (AVX2)
//! replace sixteen scalar loads.
use crate::field::lerp_index;

/// The interpolation cells and weights of every pixel column on one grid.
pub(super) struct ColumnTable {
    /// `(i0, i1, tx)` of each column, as [`lerp_index`] gives them.
    cols: Vec<(u32, u32, f32)>,
    /// The whole runs of 8 columns whose cells lie within 8 neighbouring cells: `(run, first cell)`
    /// (the others, where pixels are coarser than cells or the row is shorter than 8 cells, and the
    /// last partial run, go one column at a time).
    windows: Vec<(u32, u32)>,
    slow: Vec<u32>,
    nx: usize,
    /// `i0 - window`, `i1 - window` and `tx` of each column, padded to whole runs.
    rel0: Vec<i32>,
    rel1: Vec<i32>,
    tx: Vec<f32>,
}

impl ColumnTable {
    /// The table of pixel centres `xs` on a grid of `nx` columns of `cell` m.
    pub(super) fn new(xs: &[f32], nx: usize, cell: f32) -> ColumnTable {
        let cols: Vec<(u32, u32, f32)> = xs
            .iter()
            .map(|&x| {
                let (a, b, t) = lerp_index(x / cell - 0.5, nx);
                (a as u32, b as u32, t)
            })
            .collect();
        let runs = cols.len().div_ceil(8);
        let whole = cols.len() / 8;
        let (mut rel0, mut rel1, mut tx) =
            (vec![0; 8 * runs], vec![0; 8 * runs], vec![0.0; 8 * runs]);
        let (mut windows, mut slow) = (Vec::new(), Vec::new());
        for (r, run) in cols.chunks(8).enumerate() {
            let first = run.iter().map(|c| c.0).min().unwrap_or(0);
            let last = run.iter().map(|c| c.1).max().unwrap_or(0);
            let window = (nx as u32).checked_sub(8).map(|w| first.min(w));
            match window {
                Some(window) if r < whole && last - window < 8 => {
                    for (k, &(i0, i1, t)) in run.iter().enumerate() {
                        rel0[8 * r + k] = (i0 - window) as i32;
                        rel1[8 * r + k] = (i1 - window) as i32;
                        tx[8 * r + k] = t;
                    }
                    windows.push((r as u32, window));
                }
                _ => slow.push(r as u32),
            }
        }
        ColumnTable {
            cols,
            windows,
            slow,
            nx,
            rel0,
            rel1,
            tx,
        }
    }

    /// Row `lo` (one grid row, `nx` values) interpolated at every column into `out[..columns]`,
    /// with AVX2 if `vector` and the CPU has it.
    pub(super) fn expand(&self, lo: &[f32], out: &mut [f32], vector: bool) {
        assert!(out.len() >= self.cols.len(), "a value per column");
        assert_eq!(lo.len(), self.nx, "a row of the table's grid");
        #[cfg(target_arch = "x86_64")]
        if vector && std::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU has AVX2.
            unsafe { self.expand_avx2(lo, out) };
            for &r in &self.slow {
                self.expand_runs(lo, out, r as usize..r as usize + 1);
            }
            return;
        }
        let _ = vector;
        self.expand_runs(lo, out, 0..self.cols.len().div_ceil(8));
    }

    /// Columns of the runs `runs`, one at a time.
    #[inline(always)]
    fn expand_runs(&self, lo: &[f32], out: &mut [f32], runs: std::ops::Range<usize>) {
        let cols = 8 * runs.start..(8 * runs.end).min(self.cols.len());
        let Some(last) = lo.len().checked_sub(1) else {
            return;
        };
        for (o, &(i0, i1, tx)) in out[cols.clone()].iter_mut().zip(&self.cols[cols]) {
            // The table holds indices into the row; the `min` only spares the bounds checks.
            let (a, b) = (lo[(i0 as usize).min(last)], lo[(i1 as usize).min(last)]);
            *o = a + (b - a) * tx;
        }
    }

    /// The runs of [`ColumnTable::windows`].
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn expand_avx2(&self, lo: &[f32], out: &mut [f32]) {
        use std::arch::x86_64::*;
        for &(r, window) in &self.windows {
            let at = 8 * r as usize;
            // SAFETY: a window's 8 cells are inside the row (`window <= nx - 8`, and `lo` holds
            // `nx`, both checked), its run is whole (8 table entries and 8 outputs, `out` covering
            // every column), and the relative indices are 0..8 (made so by `new`).
            unsafe {
                let cells = _mm256_loadu_ps(lo.as_ptr().add(window as usize));
                let i0 = _mm256_loadu_si256(self.rel0.as_ptr().add(at).cast());
                let i1 = _mm256_loadu_si256(self.rel1.as_ptr().add(at).cast());
                let a = _mm256_permutevar8x32_ps(cells, i0);
                let b = _mm256_permutevar8x32_ps(cells, i1);
                let t = _mm256_loadu_ps(self.tx.as_ptr().add(at));
                let v = _mm256_add_ps(a, _mm256_mul_ps(_mm256_sub_ps(b, a), t));
                _mm256_storeu_ps(out.as_mut_ptr().add(at), v);
            }
        }
    }
}
