//! Deposits: kernel-weighted trails along segments, onto a whole grid or onto bands of its rows.
use super::{GridField, GridSpec};
use crate::field::Kernel;
use glam::Vec2;
use rayon::prelude::*;

impl GridField {
    /// Adds `amount * kernel.weight(distance to segment a-b)` to every cell near the segment.
    /// Only cells of the segment's bounding box grown by the kernel's support are visited, and of
    /// those only the ones each row can bring within the support. `a == b` is a point deposit. A
    /// kernel narrower than half a cell may touch no cell centre and deposit nothing.
    pub fn deposit_segment(&mut self, kernel: &Kernel, a: Vec2, b: Vec2, amount: f32) {
        let ny = self.spec.ny;
        self.band_mut(0, ny).deposit_segment(kernel, a, b, amount);
    }

    /// Rows `first_row..first_row + rows` (clamped to the grid) as a band that takes deposits.
    pub fn band_mut(&mut self, first_row: usize, rows: usize) -> GridBand<'_> {
        let GridSpec { nx, ny, .. } = self.spec;
        let first_row = first_row.min(ny);
        let rows = rows.min(ny - first_row);
        GridBand {
            spec: self.spec,
            first_row,
            values: &mut self.values[first_row * nx..(first_row + rows) * nx],
        }
    }

    /// The grid cut into bands of `rows` rows (the last may be shorter): deposits into different
    /// bands can run in parallel, and a cell's deposits still arrive in the order they are made
    /// when every band takes every deposit in that order.
    pub fn bands_mut(&mut self, rows: usize) -> impl Iterator<Item = GridBand<'_>> {
        let (spec, rows, cells) = self.band_cells(rows);
        self.values
            .chunks_mut(cells)
            .enumerate()
            .map(move |(k, values)| GridBand::number(spec, rows, k, values))
    }

    /// [`GridField::bands_mut`] as a parallel iterator.
    pub fn par_bands_mut(
        &mut self,
        rows: usize,
    ) -> impl IndexedParallelIterator<Item = GridBand<'_>> {
        let (spec, rows, cells) = self.band_cells(rows);
        self.values
            .par_chunks_mut(cells)
            .enumerate()
            .map(move |(k, values)| GridBand::number(spec, rows, k, values))
    }

    /// The grid, and the rows (at least one) and cells of each band for bands of `rows` rows.
    fn band_cells(&self, rows: usize) -> (GridSpec, usize, usize) {
        let rows = rows.max(1);
        (self.spec, rows, (rows * self.spec.nx).max(1))
    }

    /// Adds `amount * kernel.weight(distance to p)` to every cell near `p`.
    pub fn deposit_point(&mut self, kernel: &Kernel, p: Vec2, amount: f32) {
        self.deposit_segment(kernel, p, p, amount);
    }
}

/// Consecutive rows of a grid's values (see [`GridField::bands_mut`]): deposits land on the cells of
/// these rows only.
pub struct GridBand<'a> {
    spec: GridSpec,
    first_row: usize,
    values: &'a mut [f32],
}

impl<'a> GridBand<'a> {
    /// Band `k` of bands of `rows` rows, holding that band's `values`.
    fn number(spec: GridSpec, rows: usize, k: usize, values: &'a mut [f32]) -> Self {
        GridBand {
            spec,
            first_row: k * rows,
            values,
        }
    }
}

impl GridBand<'_> {
    /// [`GridField::deposit_segment`] restricted to this band's rows: the same additions, in the
    /// same arithmetic, on the cells the band holds.
    pub fn deposit_segment(&mut self, kernel: &Kernel, a: Vec2, b: Vec2, amount: f32) {
        let GridSpec { nx, ny, cell } = self.spec;
        let support = kernel.support();
        if !(support >= 0.0) || !a.is_finite() || !b.is_finite() {
            return;
        }
        // Deposits far from this band's rows (by more than a cell, so rounding cannot matter) are
        // skipped before any cell arithmetic: a band sees every deposit of its field.
        let band_end = self.first_row + self.values.len() / nx.max(1);
        let (band_lo, band_hi) = (self.first_row as f32 * cell, band_end as f32 * cell);
        if a.y.max(b.y) + support < band_lo - cell || a.y.min(b.y) - support > band_hi + cell {
            return;
        }
        let (j0, j1) = self
            .spec
            .cell_range(a.y.min(b.y) - support, a.y.max(b.y) + support, ny);
        let (j0, j1) = (j0.max(self.first_row), j1.min(band_end));
        if j0 >= j1 {
            return;
        }
        let (i0, i1) = self
            .spec
            .cell_range(a.x.min(b.x) - support, a.x.max(b.x) + support, nx);
        let ab = b - a;
        let len2 = ab.length_squared();
        // Most cells of the bounding box lie beyond the kernel (a disc covers a quarter of its
        // square). Per row, only cells whose centres come within `reach` of the segment's bounding
        // box are weighed: the distance to a segment is at least the distance to its bounding box,
        // and the margin over `support` dwarfs the rounding of both, so every cell the full box
        // would weigh non-zero is still weighed, with the same arithmetic.
        let reach = support * (1.0 + 1e-3) + cell * 1e-3;
        let (x_lo, x_hi) = (a.x.min(b.x), a.x.max(b.x));
        let (y_lo, y_hi) = (a.y.min(b.y), a.y.max(b.y));
        for j in j0..j1 {
            let y = (j as f32 + 0.5) * cell;
            let dy = (y_lo - y).max(y - y_hi).max(0.0);
            if dy > reach {
                continue;
            }
            let half = (reach * reach - dy * dy).max(0.0).sqrt();
            // Truncation is floor for the non-negative values here: the range may take one cell
            // more on each side, never one fewer.
            let first = ((((x_lo - half) / cell - 0.5).max(0.0)) as usize).max(i0);
            let end = ((((x_hi + half) / cell - 0.5).max(0.0)) as usize + 2).min(i1);
            let r = j - self.first_row;
            let row = &mut self.values[r * nx..(r + 1) * nx];
            for (i, v) in row.iter_mut().enumerate().take(end).skip(first) {
                let p = Vec2::new((i as f32 + 0.5) * cell, y);
                let dist = segment_distance(p, a, ab, len2);
                if dist <= support {
                    let w = kernel.weight(dist);
                    if w != 0.0 {
                        *v += amount * w;
                    }
                }
            }
        }
    }
}

/// Distance from `p` to the segment starting at `a` with direction `ab` (`len2 = |ab|^2`).
fn segment_distance(p: Vec2, a: Vec2, ab: Vec2, len2: f32) -> f32 {
    let t = if len2 > 0.0 {
        ((p - a).dot(ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p - (a + ab * t)).length()
}

/// Deposits for the property tests of banded deposits: a disc, cone or Gaussian kernel of any
/// size up to 5 cm, on a grid over 0.6 x 0.4 m with one of the scenarios' cell sizes (or an odd
/// one), along a segment of up to 6 cm from anywhere on the grid or just off it: (kernel, grid, a, b).
#[cfg(test)]
pub(crate) fn test_segments()
-> impl proptest::strategy::Strategy<Value = (Kernel, GridSpec, Vec2, Vec2)> {
    use proptest::strategy::Strategy;
    let cells = proptest::sample::select(vec![0.003f32, 0.005, 0.01, 0.0137]);
    let start = (-0.05f32..0.65, -0.05f32..0.45);
    let step = (-0.06f32..0.06, -0.06f32..0.06);
    (0usize..3, 0.0005f32..0.05, cells, start, step).prop_map(|(shape, size, cell, a, step)| {
        let kernel = match shape {
            0 => Kernel::Disc { radius: size },
            1 => Kernel::Cone { radius: size },
            _ => Kernel::Gaussian { sigma: size / 3.0 },
        };
        let spec = GridSpec::covering(Vec2::new(0.6, 0.4), cell);
        let (a, b) = (Vec2::new(a.0, a.1), Vec2::new(a.0 + step.0, a.1 + step.1));
        (kernel, spec, a, b)
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::field::GridParams;

    /// The deposit as first written: every cell of the bounding box weighed.
    fn deposit_whole_box(g: &mut GridField, kernel: &Kernel, a: Vec2, b: Vec2, amount: f32) {
        let GridSpec { nx, cell, .. } = *g.spec();
        let support = kernel.support();
        let ((i0, i1), (j0, j1)) = g.spec.segment_cells(a, b, support);
        let (ab, len2) = (b - a, (b - a).length_squared());
        for j in j0..j1 {
            for i in i0..i1 {
                let p = Vec2::new((i as f32 + 0.5) * cell, (j as f32 + 0.5) * cell);
                let dist = segment_distance(p, a, ab, len2);
                if dist <= support {
                    let w = kernel.weight(dist);
                    if w != 0.0 {
                        g.values[j * nx + i] += amount * w;
                    }
                }
            }
        }
    }

    proptest::proptest! {
        /// Deposits that weigh only the cells near the segment, in bands or whole, leave every cell
        /// bit for bit as weighing the whole bounding box does.
        #[test]
        fn deposits_equal_the_whole_box(
            (kernel, spec, a, b) in test_segments(),
            bands in 1usize..5,
        ) {
            let mut want = GridField::new(spec, GridParams::default());
            deposit_whole_box(&mut want, &kernel, a, b, 1.7);
            let mut whole = GridField::new(spec, GridParams::default());
            whole.deposit_segment(&kernel, a, b, 1.7);
            let mut banded = GridField::new(spec, GridParams::default());
            let rows = spec.ny.div_ceil(bands);
            for mut band in banded.bands_mut(rows) {
                band.deposit_segment(&kernel, a, b, 1.7);
            }
            let bits = |g: &GridField| g.values().iter().map(|v| v.to_bits()).collect::<Vec<_>>();
            proptest::prop_assert_eq!(bits(&whole), bits(&want));
            proptest::prop_assert_eq!(bits(&banded), bits(&want));
        }
    }
}
