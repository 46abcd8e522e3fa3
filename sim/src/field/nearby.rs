//! A group of points close together (a robot's sensor footprints) seen from their centroid: the
//! offsets every Gaussian source's shared `exp` needs ([`super::FrozenSource::add_values_near`]),
//! computed once per group.

/// A group of at most `G` points close together (a robot's footprints), seen from their centroid:
/// the offsets, their squares and products, and their largest magnitudes, computed once and shared
/// by every Gaussian source ([`super::FrozenSource::add_values_near`]).
pub struct NearbyPoints<const G: usize> {
    pub(super) len: usize,
    pub(super) centroid: (f32, f32),
    pub(super) max_offset: (f32, f32),
    pub(super) ex: [f32; G],
    pub(super) ey: [f32; G],
    pub(super) exx: [f32; G],
    pub(super) eyy: [f32; G],
    pub(super) exy: [f32; G],
}

impl<const G: usize> NearbyPoints<G> {
    /// The first `G` of the points `(xs[k], ys[k])`.
    #[inline(always)]
    pub fn new(xs: &[f32], ys: &[f32]) -> Self {
        let n = xs.len().min(ys.len()).min(G);
        let (xs, ys) = (&xs[..n], &ys[..n]);
        // The centroid summed in eight interleaved lanes (vectorises; a plain running sum is one long
        // chain of dependent additions). A single point is its own centroid.
        let (mut sx, mut sy) = ([0f32; 8], [0f32; 8]);
        for (xs, ys) in xs.chunks(8).zip(ys.chunks(8)) {
            for (k, (&x, &y)) in xs.iter().zip(ys).enumerate() {
                sx[k] += x;
                sy[k] += y;
            }
        }
        let inv_n = 1.0 / n.max(1) as f32;
        let (cx, cy) = (
            sx.iter().sum::<f32>() * inv_n,
            sy.iter().sum::<f32>() * inv_n,
        );
        let mut near = Self::about(n, (cx, cy));
        // Largest magnitudes as integers: the bits of non-negative floats order as the floats (and a
        // NaN offset, above infinity, makes the bound NaN: the per-point path).
        let (mut mx, mut my) = (0u32, 0u32);
        for k in 0..n {
            let (ex, ey) = (xs[k] - cx, ys[k] - cy);
            near.ex[k] = ex;
            near.ey[k] = ey;
            near.exx[k] = ex * ex;
            near.eyy[k] = ey * ey;
            near.exy[k] = ex * ey;
            mx = mx.max(ex.abs().to_bits());
            my = my.max(ey.abs().to_bits());
        }
        near.max_offset = (f32::from_bits(mx), f32::from_bits(my));
        near
    }
}

impl<const G: usize> NearbyPoints<G> {
    /// `n` points about `centroid`, their offsets still to be filled in.
    #[inline]
    fn about(n: usize, centroid: (f32, f32)) -> Self {
        NearbyPoints {
            len: n,
            centroid,
            max_offset: (0.0, 0.0),
            ex: [0.0; G],
            ey: [0.0; G],
            exx: [0.0; G],
            eyy: [0.0; G],
            exy: [0.0; G],
        }
    }

    /// [`NearbyPoints::new`] of the first `n` points, bit for bit, for arrays whose lanes past `n`
    /// repeat lane 0 (a robot's 36 footprint samples padded to whole vectors) and `G` a multiple of
    /// eight: every lane's offsets are computed (no tail loop), and the padding leaves the largest
    /// offsets unchanged. The centroid sums the first `n` points in `new`'s eight interleaved lanes
    /// and order. Written with AVX2 intrinsics: the compiler paired the x and y sums into 2-lane code
    /// that cost a third of a robot's footprint evaluation.
    ///
    /// # Safety
    /// The CPU has AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    #[inline]
    pub unsafe fn of_padded_avx2(xs: &[f32; G], ys: &[f32; G], n: usize) -> Self {
        use std::arch::x86_64::*;
        const { assert!(G.is_multiple_of(8) && G > 0) };
        let n = n.clamp(1, G);
        let inv_n = 1.0 / n as f32;
        // SAFETY: the CPU has AVX2 (this function's contract), `G` is a multiple of eight (checked
        // above) and `n <= G`.
        let (sx, sy) = unsafe { (interleaved_sum_avx2(xs, n), interleaved_sum_avx2(ys, n)) };
        // `new` adds the eight lane sums in order (`sum()` starts from -0, which adds nothing): x and
        // y side by side in the two low lanes, one addition per lane sum.
        let (lo, hi) = (_mm256_unpacklo_ps(sx, sy), _mm256_unpackhi_ps(sx, sy));
        // Per 128-bit half, `lo` holds lanes (0, 1) and (4, 5) of x and y interleaved, `hi` (2, 3)
        // and (6, 7).
        let quads = [
            _mm256_castps256_ps128(lo),
            _mm256_castps256_ps128(hi),
            _mm256_extractf128_ps::<1>(lo),
            _mm256_extractf128_ps::<1>(hi),
        ];
        let mut sum = quads[0];
        sum = _mm_add_ps(sum, _mm_movehl_ps(sum, sum));
        for q in &quads[1..] {
            sum = _mm_add_ps(sum, *q);
            sum = _mm_add_ps(sum, _mm_movehl_ps(*q, *q));
        }
        let c = _mm_mul_ps(sum, _mm_set1_ps(inv_n));
        let (cx, cy) = (_mm_cvtss_f32(c), _mm_cvtss_f32(_mm_movehdup_ps(c)));
        let mut near = Self::about(n, (cx, cy));
        let (vcx, vcy) = (_mm256_set1_ps(cx), _mm256_set1_ps(cy));
        let sign = _mm256_set1_ps(-0.0);
        let (mut mx, mut my) = (_mm256_setzero_si256(), _mm256_setzero_si256());
        for k in (0..G).step_by(8) {
            // SAFETY: `k + 8 <= G` for every array read and written.
            unsafe {
                let ex = _mm256_sub_ps(_mm256_loadu_ps(xs.as_ptr().add(k)), vcx);
                let ey = _mm256_sub_ps(_mm256_loadu_ps(ys.as_ptr().add(k)), vcy);
                _mm256_storeu_ps(near.ex.as_mut_ptr().add(k), ex);
                _mm256_storeu_ps(near.ey.as_mut_ptr().add(k), ey);
                _mm256_storeu_ps(near.exx.as_mut_ptr().add(k), _mm256_mul_ps(ex, ex));
                _mm256_storeu_ps(near.eyy.as_mut_ptr().add(k), _mm256_mul_ps(ey, ey));
                _mm256_storeu_ps(near.exy.as_mut_ptr().add(k), _mm256_mul_ps(ex, ey));
                // Largest magnitudes as integers, as in `new`.
                mx = _mm256_max_epu32(mx, _mm256_castps_si256(_mm256_andnot_ps(sign, ex)));
                my = _mm256_max_epu32(my, _mm256_castps_si256(_mm256_andnot_ps(sign, ey)));
            }
        }
        // Both maxima reduced together: x in the low 128-bit half, y in the high one.
        let m = _mm256_max_epu32(
            _mm256_permute2x128_si256::<0x20>(mx, my),
            _mm256_permute2x128_si256::<0x31>(mx, my),
        );
        let m = _mm256_max_epu32(m, _mm256_shuffle_epi32::<0b01_00_11_10>(m));
        let m = _mm256_max_epu32(m, _mm256_shuffle_epi32::<0b10_11_00_01>(m));
        near.max_offset = (
            f32::from_bits(_mm256_extract_epi32::<0>(m) as u32),
            f32::from_bits(_mm256_extract_epi32::<4>(m) as u32),
        );
        near
    }
}

/// The first `n` of `v` summed in eight interleaved lanes, lane `l` taking `v[l], v[l + 8], ..` in
/// order: [`NearbyPoints::new`]'s centroid sums. The last chunk adds zeros past `n` (adding +0
/// changes no lane: a lane starts at +0 and so never holds -0).
///
/// # Safety
/// The CPU has AVX2; `G` is a multiple of eight and `n <= G`.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[inline]
unsafe fn interleaved_sum_avx2<const G: usize>(
    v: &[f32; G],
    n: usize,
) -> std::arch::x86_64::__m256 {
    use std::arch::x86_64::*;
    let mut sum = _mm256_setzero_ps();
    let mut from = 0;
    while from < n {
        let lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
        let inside = _mm256_cmpgt_epi32(_mm256_set1_epi32((n - from) as i32), lane);
        // SAFETY: `from + 8 <= G` (`from < n <= G`, both multiples of eight apart from `n`).
        let chunk = unsafe { _mm256_loadu_ps(v.as_ptr().add(from)) };
        sum = _mm256_add_ps(sum, _mm256_and_ps(chunk, _mm256_castsi256_ps(inside)));
        from += 8;
    }
    sum
}
