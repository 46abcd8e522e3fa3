//! Bilinear interpolation of grid fields at a fixed set of points (a robot's sensor footprints),
//! arranged so that the loops vectorise: each point's corner cells and weights are computed once, in
//! arrays, and reused by every field on the same grid.
use super::grid::{GridField, GridSpec, bilinear_mix};
use glam::Vec2;

/// The corners and weights of `N` points on one grid spec, structure of arrays. Indices are `i32`
/// (the lanes AVX2 converts, multiplies and gathers with).
pub(crate) struct GridSampler<const N: usize> {
    spec: Option<GridSpec>,
    /// Flat index (`j0 * nx + i0`) of each point's lower-left corner cell.
    base: [i32; N],
    /// `i1 - i0`: 1 inside the grid, 0 where the point clamps to an edge column.
    step_x: [i32; N],
    /// `(j1 - j0) * nx`: one row inside the grid, 0 where the point clamps to an edge row.
    step_y: [i32; N],
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
    pub(crate) fn values(
        &mut self,
        g: &GridField,
        xs: &[f32; N],
        ys: &[f32; N],
        out: &mut [f32; N],
    ) {
        let spec = *g.spec();
        let GridSpec { nx, ny, .. } = spec;
        // Flat indices fit 31 bits on every grid a scenario allows (2e8 cells); a larger grid built
        // through the API takes the per-point path.
        if nx == 0 || ny == 0 || nx.saturating_mul(ny) > i32::MAX as usize {
            for ((o, &x), &y) in out.iter_mut().zip(xs).zip(ys) {
                *o = g.value_at(Vec2::new(x, y));
            }
            return;
        }
        if self.spec != Some(spec) {
            self.weigh(spec, xs, ys);
        }
        let v = g.values();
        assert_eq!(v.len(), nx * ny, "a grid holds one value per cell");
        #[cfg(target_arch = "x86_64")]
        if std::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU has AVX2; `weigh` clamped every corner into the grid, whose length
            // was checked above.
            unsafe { self.gather_avx2(v, out) };
            return;
        }
        self.interpolate_from(v, 0, out);
    }

    /// The interpolation of points `from..N`, one at a time.
    #[inline(always)]
    fn interpolate_from(&self, v: &[f32], from: usize, out: &mut [f32; N]) {
        for (k, o) in out.iter_mut().enumerate().skip(from) {
            let b = self.base[k] as usize;
            let (sx, sy) = (self.step_x[k] as usize, self.step_y[k] as usize);
            *o = bilinear_mix(
                v[b],
                v[b + sx],
                v[b + sy],
                v[b + sy + sx],
                self.tx[k],
                self.ty[k],
            );
        }
    }

    /// The interpolation of [`GridSampler::values`], eight points at a time with AVX2 gathers: the
    /// same operations in the same order as [`bilinear_mix`] (no fused multiply-add), so the same
    /// values bit for bit (tested against the per-point reference).
    ///
    /// # Safety
    /// The CPU has AVX2, and every corner index of the weighed points is below `v.len()`.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn gather_avx2(&self, v: &[f32], out: &mut [f32; N]) {
        use std::arch::x86_64::*;
        const LANES: usize = 8;
        let whole = N / LANES * LANES;
        let p = v.as_ptr();
        // Lanes `k..` of the points with one width's intrinsics: loads, corner indices, gathers,
        // `bilinear_mix`'s three blends, store.
        macro_rules! interpolate {
            (
                $k:expr; load = $load_i:ident, $load_f:ident, add = $add_i:ident,
                gather = $gather:ident, blend = $add:ident, $sub:ident, $mul:ident,
                store = $store:ident
            ) => {{
                let k = $k;
                let load_i = |a: &[i32; N]| $load_i(a.as_ptr().add(k).cast());
                let load_f = |a: &[f32; N]| $load_f(a.as_ptr().add(k));
                let b = load_i(&self.base);
                let b10 = $add_i(b, load_i(&self.step_x));
                let b01 = $add_i(b, load_i(&self.step_y));
                let b11 = $add_i(b01, load_i(&self.step_x));
                let v00 = $gather::<4>(p, b);
                let v10 = $gather::<4>(p, b10);
                let v01 = $gather::<4>(p, b01);
                let v11 = $gather::<4>(p, b11);
                let (tx, ty) = (load_f(&self.tx), load_f(&self.ty));
                let lo = $add(v00, $mul($sub(v10, v00), tx));
                let hi = $add(v01, $mul($sub(v11, v01), tx));
                let r = $add(lo, $mul($sub(hi, lo), ty));
                $store(out.as_mut_ptr().add(k), r);
            }};
        }
        for k in (0..whole).step_by(LANES) {
            // SAFETY: `k + 8 <= N` for every array read and written; the corner indices are in
            // bounds (the caller's contract).
            unsafe {
                interpolate! {
                    k; load = _mm256_loadu_si256, _mm256_loadu_ps, add = _mm256_add_epi32,
                    gather = _mm256_i32gather_ps, blend = _mm256_add_ps, _mm256_sub_ps,
                    _mm256_mul_ps, store = _mm256_storeu_ps
                }
            }
        }
        // A four-point remainder (a robot's 36 footprint samples) in one 128-bit gather.
        let mut done = whole;
        if N - whole >= 4 {
            // SAFETY: as above, with `whole + 4 <= N`.
            unsafe {
                interpolate! {
                    whole; load = _mm_loadu_si128, _mm_loadu_ps, add = _mm_add_epi32,
                    gather = _mm_i32gather_ps, blend = _mm_add_ps, _mm_sub_ps, _mm_mul_ps,
                    store = _mm_storeu_ps
                }
            }
            done += 4;
        }
        self.interpolate_from(v, done, out);
    }

    /// Corners and weights of every point on `spec` (`nx, ny >= 1`, `nx * ny` within 31 bits).
    #[inline(always)]
    fn weigh(&mut self, spec: GridSpec, xs: &[f32; N], ys: &[f32; N]) {
        let (nx, ny) = (spec.nx as i32, spec.ny as i32);
        let cell = spec.cell;
        for k in 0..N {
            let (i0, di, tx) = lerp_lane(xs[k] / cell - 0.5, nx);
            let (j0, dj, ty) = lerp_lane(ys[k] / cell - 0.5, ny);
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
fn lerp_lane(f: f32, n: i32) -> (i32, i32, f32) {
    let max = (n - 1) as f32;
    let inside = f > 0.0 && f < max;
    let c = if f > 0.0 { f.min(max) } else { 0.0 };
    // SAFETY: `c` is in [0, n - 1] (NaN went to 0 above), so the truncation is in range.
    let t = unsafe { c.to_int_unchecked::<i32>() };
    // `inside` implies n >= 2, so `n - 2` is a valid index where it is selected.
    let i0 = if inside { t.min(n - 2) } else { t };
    let frac = if inside { c - i0 as f32 } else { 0.0 };
    (i0, i32::from(inside), frac)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::field::lerp_index;

    /// The gathered path (AVX2 where the processor has it), the scalar loop over every point and
    /// `value_at` give the same bits, inside the grid, on its edges and beyond them.
    #[test]
    fn gathered_scalar_and_pointwise_values_agree() {
        use crate::field::GridParams;
        use rand::{RngExt, SeedableRng};
        let mut rng = rand::rngs::SmallRng::seed_from_u64(5);
        for (nx, ny) in [(1, 1), (2, 3), (37, 23), (200, 120)] {
            let spec = GridSpec::new(nx, ny, 0.01);
            let mut g = GridField::new(spec, GridParams::default());
            g.values_mut()
                .iter_mut()
                .for_each(|v| *v = rng.random_range(0.0..2.0));
            let (w, h) = (nx as f32 * 0.01, ny as f32 * 0.01);
            for _ in 0..50 {
                let xs: [f32; 36] = std::array::from_fn(|_| rng.random_range(-0.02..w + 0.02));
                let ys: [f32; 36] = std::array::from_fn(|_| rng.random_range(-0.02..h + 0.02));
                let mut sampler = GridSampler::<36>::new();
                let mut gathered = [0.0; 36];
                sampler.values(&g, &xs, &ys, &mut gathered);
                let mut scalar = [0.0; 36];
                sampler.interpolate_from(g.values(), 0, &mut scalar);
                for k in 0..36 {
                    let want = g.value_at(Vec2::new(xs[k], ys[k]));
                    assert_eq!(
                        gathered[k].to_bits(),
                        want.to_bits(),
                        "point {k} on {nx}x{ny}"
                    );
                    assert_eq!(
                        scalar[k].to_bits(),
                        want.to_bits(),
                        "point {k} on {nx}x{ny}"
                    );
                }
            }
        }
    }

    #[test]
    fn lerp_lane_matches_lerp_index() {
        for n in [1i32, 2, 3, 10] {
            for f in [
                -1.0,
                -0.0,
                0.0,
                1e-7,
                0.5,
                1.0,
                1.5,
                7.999,
                8.0,
                8.5,
                9.0,
                100.0,
                f32::NAN,
            ] {
                let (i0, i1, t) = lerp_index(f, n as usize);
                let (b, d, tl) = lerp_lane(f, n);
                assert_eq!((b as usize, (b + d) as usize), (i0, i1), "f = {f}, n = {n}");
                assert_eq!(tl.to_bits(), t.to_bits(), "f = {f}, n = {n}");
            }
        }
    }
}
