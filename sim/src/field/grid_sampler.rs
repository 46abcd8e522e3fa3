//! Bilinear interpolation of grid fields at a fixed set of points (a robot's sensor footprints),
//! arranged so that the loops vectorise: each point's corner cells and weights are computed once, in
//! arrays, and reused by every field on the same grid.
use super::grid::{GridField, GridSpec, bilinear_mix};
use glam::Vec2;

/// The corners and weights of `N` points on one grid spec, structure of arrays.
pub(crate) struct GridSampler<const N: usize> {
    spec: Option<GridSpec>,
    /// Flat index (`j0 * nx + i0`) of each point's lower-left corner cell.
    base: [u32; N],
    /// `i1 - i0`: 1 inside the grid, 0 where the point clamps to an edge column.
    step_x: [u32; N],
    /// `(j1 - j0) * nx`: one row inside the grid, 0 where the point clamps to an edge row.
    step_y: [u32; N],
    tx: [f32; N],
    ty: [f32; N],
}

impl<const N: usize> GridSampler<N> {
    pub(crate) fn new() -> Self {
        GridSampler {
            spec: None,
            base: [0; N],
            step_x: [0; N],
            step_y: [0; N],
            tx: [0.0; N],
            ty: [0.0; N],
        }
    }

    /// `g`'s bilinear values at the points `(xs[k], ys[k])`: the same values, bit for bit, as
    /// [`GridField::value_at`] (same clamping, same arithmetic).
    #[inline(always)]
    pub(crate) fn values(&mut self, g: &GridField, xs: &[f32; N], ys: &[f32; N], out: &mut [f32; N]) {
        let spec = *g.spec();
        let GridSpec { nx, ny, .. } = spec;
        if nx == 0 || ny == 0 {
            out.fill(0.0);
            return;
        }
        // Flat indices fit 32 bits on every grid a scenario allows (2e8 cells); a larger grid built
        // through the API takes the per-point path.
        if nx.saturating_mul(ny) > u32::MAX as usize {
            for ((o, &x), &y) in out.iter_mut().zip(xs).zip(ys) {
                *o = g.value_at(Vec2::new(x, y));
            }
            return;
        }
        if self.spec != Some(spec) {
            self.weigh(spec, xs, ys);
        }
        let v = g.values();
        for k in 0..N {
            let b = self.base[k] as usize;
            let (sx, sy) = (self.step_x[k] as usize, self.step_y[k] as usize);
            out[k] = bilinear_mix(
                v[b],
                v[b + sx],
                v[b + sy],
                v[b + sy + sx],
                self.tx[k],
                self.ty[k],
            );
        }
    }

    /// Corners and weights of every point on `spec` (`nx, ny >= 1`, `nx * ny` within 32 bits).
    #[inline(always)]
    fn weigh(&mut self, spec: GridSpec, xs: &[f32; N], ys: &[f32; N]) {
        let (nx, ny) = (spec.nx as u32, spec.ny as u32);
        for k in 0..N {
            let (i0, di, tx) = lerp_lane(xs[k] / spec.cell - 0.5, nx);
            let (j0, dj, ty) = lerp_lane(ys[k] / spec.cell - 0.5, ny);
            self.base[k] = j0 * nx + i0;
            self.step_x[k] = di;
            self.step_y[k] = dj * nx;
            self.tx[k] = tx;
            self.ty[k] = ty;
        }
        self.spec = Some(spec);
    }
}

/// `lerp_index` (the grid's clamped interpolation index) without branches, so that it vectorises:
/// `(i0, i1 - i0, t)` for fractional index `f` on `n >= 1` samples. Below the first sample (or NaN)
/// gives `(0, 0, 0)`, at or past the last `(n - 1, 0, 0)`, inside `(min(floor f, n - 2), 1, f - i0)`.
#[inline(always)]
fn lerp_lane(f: f32, n: u32) -> (u32, u32, f32) {
    let max = (n - 1) as f32;
    let inside = f > 0.0 && f < max;
    let c = if f > 0.0 { f.min(max) } else { 0.0 };
    // SAFETY: `c` is in [0, n - 1] (NaN went to 0 above), so the truncation is in range.
    let t = unsafe { c.to_int_unchecked::<i32>() } as u32;
    // `inside` implies n >= 2; elsewhere the wrapped value is not selected.
    let i0 = if inside { t.min(n.wrapping_sub(2)) } else { t };
    let frac = if inside { c - i0 as f32 } else { 0.0 };
    (i0, u32::from(inside), frac)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::field::lerp_index;

    #[test]
    fn lerp_lane_matches_lerp_index() {
        for n in [1u32, 2, 3, 10] {
            for f in [-1.0, -0.0, 0.0, 1e-7, 0.5, 1.0, 1.5, 7.999, 8.0, 8.5, 9.0, 100.0, f32::NAN] {
                let (i0, i1, t) = lerp_index(f, n as usize);
                let (b, d, tl) = lerp_lane(f, n);
                assert_eq!((b as usize, (b + d) as usize), (i0, i1), "f = {f}, n = {n}");
                assert_eq!(tl.to_bits(), t.to_bits(), "f = {f}, n = {n}");
            }
        }
    }
}
