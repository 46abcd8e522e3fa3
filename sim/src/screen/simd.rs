//! The pixel row of grid pheromones in vector registers, 8 (AVX2) or 16 (AVX-512) pixels at a time:
//! each grid's two expanded rows blended, weighted into the three channels, turned into levels and
//! packed as RGB bytes without leaving the registers. The operations and their order are those of
//! eq. (1)'s scalar form ([`super::to_level`] included), and Rust never fuses a multiply and an add,
//! so the bytes are the same.
#![cfg(target_arch = "x86_64")]
use std::arch::x86_64::*;
use std::mem::MaybeUninit;

/// Grid pheromones one pass takes; more go through the portable blocks.
pub(super) const MAX_TERMS: usize = 8;

/// The widest kernel this CPU runs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Level {
    Avx2,
    /// With byte permutes (VBMI) and masked byte stores (BW).
    Avx512,
}

pub(super) fn level() -> Option<Level> {
    if std::is_x86_feature_detected!("avx512f")
        && std::is_x86_feature_detected!("avx512bw")
        && std::is_x86_feature_detected!("avx512vbmi")
    {
        Some(Level::Avx512)
    } else if std::is_x86_feature_detected!("avx2") {
        Some(Level::Avx2)
    } else {
        None
    }
}

/// One grid pheromone's part of a pixel row: `lo[px] + (hi[px] - lo[px]) ty`.
#[derive(Clone, Copy)]
pub(super) struct Term<'a> {
    pub(super) lo: &'a [f32],
    pub(super) hi: &'a [f32],
    pub(super) ty: f32,
}

impl Term<'_> {
    pub(super) const NONE: Term<'static> = Term {
        lo: &[],
        hi: &[],
        ty: 0.0,
    };
}

/// What each channel adds up, in pheromone order: `(term, colour weight)`. Zero weights of bounded
/// grids are left out (they add an exact zero).
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Products {
    pub(super) list: [[(u8, f32); MAX_TERMS]; 3],
    pub(super) len: [u8; 3],
}

impl Products {
    /// Each channel adds up at most one product: `(term, weight)` per channel, if any.
    pub(super) fn single(&self) -> Option<[Option<(u8, f32)>; 3]> {
        let mut out = [None; 3];
        for ((o, list), &n) in out.iter_mut().zip(&self.list).zip(&self.len) {
            match n {
                0 => {}
                1 => *o = Some(list[0]),
                _ => return None,
            }
        }
        Some(out)
    }

    pub(super) fn push(&mut self, channel: usize, term: usize, k: f32) {
        let n = self.len[channel] as usize;
        self.list[channel][n] = (term as u8, k);
        self.len[channel] += 1;
    }
}

/// Writes the pixel row of `terms` into `out` (3 bytes a pixel). Every term's rows hold at least
/// `out.len() / 3` values rounded up to a multiple of 16 (the padding is read, not shown).
pub(super) fn grid_row(
    level: Level,
    terms: &[Term],
    products: &Products,
    out: &mut [MaybeUninit<u8>],
) {
    let groups = (out.len() / 3).div_ceil(16);
    assert!(terms.len() <= MAX_TERMS, "at most {MAX_TERMS} terms");
    for t in terms {
        assert!(
            t.lo.len() >= 16 * groups && t.hi.len() >= 16 * groups,
            "expanded rows cover the padded width"
        );
    }
    for (list, &n) in products.list.iter().zip(&products.len) {
        assert!(
            list[..n as usize]
                .iter()
                .all(|&(t, _)| (t as usize) < terms.len())
        );
    }
    // SAFETY: `level` comes from `level()`, which checked these features; the rows and products
    // were checked above.
    unsafe {
        match level {
            Level::Avx2 => row_avx2(terms, products, out),
            Level::Avx512 => row_avx512(terms, products, out),
        }
    }
}

/// One channel's single product in a pixel row: `k (lo[px] + (hi[px] - lo[px]) ty)` (a channel
/// nothing adds to reads zeros with weight 0).
#[derive(Clone, Copy)]
pub(super) struct Channel<'a> {
    pub(super) term: Term<'a>,
    pub(super) k: f32,
}

/// [`grid_row`] where each channel adds up at most one product (`k v`, as the products' first):
/// no intermediate leaves the registers.
pub(super) fn channel_row(level: Level, channels: &[Channel; 3], out: &mut [MaybeUninit<u8>]) {
    let groups = (out.len() / 3).div_ceil(16);
    for c in channels {
        assert!(
            c.term.lo.len() >= 16 * groups && c.term.hi.len() >= 16 * groups,
            "rows cover the padded width"
        );
    }
    // SAFETY: as in `grid_row`.
    unsafe {
        match level {
            Level::Avx2 => channel_row_avx2(channels, out),
            Level::Avx512 => channel_row_avx512(channels, out),
        }
    }
}

#[target_feature(enable = "avx2")]
unsafe fn channel_row_avx2(channels: &[Channel; 3], out: &mut [MaybeUninit<u8>]) {
    unsafe { channels_row::<Avx2>(channels, out) }
}

#[target_feature(enable = "avx512f,avx512bw,avx512vbmi")]
unsafe fn channel_row_avx512(channels: &[Channel; 3], out: &mut [MaybeUninit<u8>]) {
    unsafe { channels_row::<Avx512>(channels, out) }
}

#[inline(always)]
unsafe fn channels_row<L: Lanes>(channels: &[Channel; 3], out: &mut [MaybeUninit<u8>]) {
    let w = out.len() / 3;
    let dst = out.as_mut_ptr().cast::<u8>();
    let [c0, c1, c2] = *channels;
    let lanes = |c: Channel, at: usize| unsafe {
        let a = L::load(c.term.lo.as_ptr().add(at));
        let b = L::load(c.term.hi.as_ptr().add(at));
        let v = L::add(a, L::mul(L::sub(b, a), L::splat(c.term.ty)));
        L::mul(L::splat(c.k), v)
    };
    let whole = w / L::N;
    for g in 0..whole {
        let at = g * L::N;
        unsafe {
            L::store_rgb(
                [lanes(c0, at), lanes(c1, at), lanes(c2, at)],
                dst.add(3 * at),
                L::N,
            )
        };
    }
    if whole * L::N < w {
        let at = whole * L::N;
        unsafe {
            L::store_rgb(
                [lanes(c0, at), lanes(c1, at), lanes(c2, at)],
                dst.add(3 * at),
                w - at,
            )
        };
    }
}

#[target_feature(enable = "avx2")]
unsafe fn row_avx2(terms: &[Term], products: &Products, out: &mut [MaybeUninit<u8>]) {
    unsafe { row::<Avx2>(terms, products, out) }
}

#[target_feature(enable = "avx512f,avx512bw,avx512vbmi")]
unsafe fn row_avx512(terms: &[Term], products: &Products, out: &mut [MaybeUninit<u8>]) {
    unsafe { row::<Avx512>(terms, products, out) }
}

/// One register of `N` f32 lanes and what the row needs of it.
trait Lanes {
    const N: usize;
    type F: Copy;
    unsafe fn zero() -> Self::F;
    unsafe fn splat(x: f32) -> Self::F;
    unsafe fn load(p: *const f32) -> Self::F;
    unsafe fn add(a: Self::F, b: Self::F) -> Self::F;
    unsafe fn sub(a: Self::F, b: Self::F) -> Self::F;
    unsafe fn mul(a: Self::F, b: Self::F) -> Self::F;
    /// The levels of `N` pixels as RGB bytes into `out[..3 n]`, `n <= N`, writing nothing past it.
    unsafe fn store_rgb(acc: [Self::F; 3], out: *mut u8, n: usize);
}

#[inline(always)]
unsafe fn row<L: Lanes>(terms: &[Term], products: &Products, out: &mut [MaybeUninit<u8>]) {
    let w = out.len() / 3;
    let dst = out.as_mut_ptr().cast::<u8>();
    let mut v = [unsafe { L::zero() }; MAX_TERMS];
    for g in 0..w.div_ceil(L::N) {
        let at = g * L::N;
        unsafe {
            for (v, t) in v.iter_mut().zip(terms) {
                let a = L::load(t.lo.as_ptr().add(at));
                let b = L::load(t.hi.as_ptr().add(at));
                *v = L::add(a, L::mul(L::sub(b, a), L::splat(t.ty)));
            }
            // `0 + p` is `p` but for the sign of a zero, which no level shows: each channel starts
            // from its first product.
            let mut acc = [L::zero(); 3];
            for ((acc, list), &n) in acc.iter_mut().zip(&products.list).zip(&products.len) {
                if let Some((&(t, k), rest)) = list[..n as usize].split_first() {
                    *acc = L::mul(L::splat(k), v[t as usize]);
                    for &(t, k) in rest {
                        *acc = L::add(*acc, L::mul(L::splat(k), v[t as usize]));
                    }
                }
            }
            L::store_rgb(acc, dst.add(3 * at), L::N.min(w - at));
        }
    }
}

/// A [`Lanes`] of `$n` lanes in register `$f`: each operation one intrinsic (the AVX2 and AVX-512
/// kinds differ only in their widths and in `$store`, their packing of the levels).
macro_rules! lanes {
    (
        $name:ident: $n:literal of $f:ty, zero = $zero:ident, splat = $splat:ident,
        load = $load:ident, add = $add:ident, sub = $sub:ident, mul = $mul:ident, store = $store:ident
    ) => {
        struct $name;

        impl Lanes for $name {
            const N: usize = $n;
            type F = $f;
            #[inline(always)]
            unsafe fn zero() -> $f {
                unsafe { $zero() }
            }
            #[inline(always)]
            unsafe fn splat(x: f32) -> $f {
                unsafe { $splat(x) }
            }
            #[inline(always)]
            unsafe fn load(p: *const f32) -> $f {
                unsafe { $load(p) }
            }
            #[inline(always)]
            unsafe fn add(a: $f, b: $f) -> $f {
                unsafe { $add(a, b) }
            }
            #[inline(always)]
            unsafe fn sub(a: $f, b: $f) -> $f {
                unsafe { $sub(a, b) }
            }
            #[inline(always)]
            unsafe fn mul(a: $f, b: $f) -> $f {
                unsafe { $mul(a, b) }
            }
            #[inline(always)]
            unsafe fn store_rgb(acc: [$f; 3], out: *mut u8, n: usize) {
                unsafe { $store(acc, out, n) }
            }
        }
    };
}

lanes! {
    Avx2: 8 of __m256, zero = _mm256_setzero_ps, splat = _mm256_set1_ps, load = _mm256_loadu_ps,
    add = _mm256_add_ps, sub = _mm256_sub_ps, mul = _mm256_mul_ps, store = store_rgb_avx2
}

/// [`Lanes::store_rgb`] of eight pixels.
#[inline(always)]
unsafe fn store_rgb_avx2(acc: [__m256; 3], out: *mut u8, n: usize) {
    unsafe {
        let (r, g, b) = (
            levels_avx2(acc[0]),
            levels_avx2(acc[1]),
            levels_avx2(acc[2]),
        );
        // Unsigned-saturating packs clip the levels to 0..=255 (negatives and NaN's i32::MIN to 0).
        let rg = _mm256_packus_epi32(r, g);
        let bytes = _mm256_packus_epi16(rg, _mm256_packus_epi32(b, b));
        // Per 128-bit half: r0..r3 g0..g3 b0..b3 b0..b3 -> r0 g0 b0 r1 ... b3 and 4 spare bytes.
        let shuffle = _mm256_setr_epi8(
            0, 4, 8, 1, 5, 9, 2, 6, 10, 3, 7, 11, -1, -1, -1, -1, 0, 4, 8, 1, 5, 9, 2, 6, 10, 3, 7,
            11, -1, -1, -1, -1,
        );
        let rgb = _mm256_shuffle_epi8(bytes, shuffle);
        let mut tmp = [0u8; 32];
        let to = if n == 8 { out } else { tmp.as_mut_ptr() };
        _mm_storeu_si128(to.cast(), _mm256_castsi256_si128(rgb));
        // 12 bytes only: the spare bytes of the first store get overwritten, nothing past.
        let second = _mm256_extracti128_si256::<1>(rgb);
        _mm_storel_epi64(to.add(12).cast(), second);
        let last = _mm_extract_epi32::<2>(second) as u32;
        std::ptr::copy_nonoverlapping(last.to_le_bytes().as_ptr(), to.add(20), 4);
        if n < 8 {
            std::ptr::copy_nonoverlapping(tmp.as_ptr(), out, 3 * n);
        }
    }
}

/// [`super::to_level`] of eight levels as i32, before the packs clip: `min(255, x)` keeps NaN (the
/// second operand), which truncates to `i32::MIN`, as negative levels truncate to at most 0; in
/// 0..=255 it rounds half away from zero as `to_level` does.
#[inline(always)]
unsafe fn levels_avx2(x: __m256) -> __m256i {
    unsafe {
        let c = _mm256_min_ps(_mm256_set1_ps(255.0), x);
        let t = _mm256_cvttps_epi32(c);
        let frac = _mm256_sub_ps(c, _mm256_cvtepi32_ps(t));
        let up = _mm256_cmp_ps::<_CMP_GE_OQ>(frac, _mm256_set1_ps(0.5));
        // `up` is all ones (-1) where the level rounds up.
        _mm256_sub_epi32(t, _mm256_castps_si256(up))
    }
}

lanes! {
    Avx512: 16 of __m512, zero = _mm512_setzero_ps, splat = _mm512_set1_ps,
    load = _mm512_loadu_ps, add = _mm512_add_ps, sub = _mm512_sub_ps, mul = _mm512_mul_ps,
    store = store_rgb_avx512
}

/// [`Lanes::store_rgb`] of sixteen pixels.
#[inline(always)]
unsafe fn store_rgb_avx512(acc: [__m512; 3], out: *mut u8, n: usize) {
    unsafe {
        // One byte a level: r, g, b, 16 apiece.
        let r = _mm512_cvtepi32_epi8(levels_avx512(acc[0]));
        let g = _mm512_cvtepi32_epi8(levels_avx512(acc[1]));
        let b = _mm512_cvtepi32_epi8(levels_avx512(acc[2]));
        let planes =
            _mm512_inserti32x4::<2>(_mm512_inserti32x4::<1>(_mm512_castsi128_si512(r), g), b);
        // Byte 3 i + c of the pixels is byte 16 c + i of the planes.
        let index = _mm512_set_epi8(
            0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, //
            47, 31, 15, 46, 30, 14, 45, 29, 13, 44, 28, 12, 43, 27, 11, 42, //
            26, 10, 41, 25, 9, 40, 24, 8, 39, 23, 7, 38, 22, 6, 37, 21, //
            5, 36, 20, 4, 35, 19, 3, 34, 18, 2, 33, 17, 1, 32, 16, 0,
        );
        let rgb = _mm512_permutexvar_epi8(index, planes);
        let mask = (1u64 << (3 * n)) - 1;
        _mm512_mask_storeu_epi8(out.cast(), mask, rgb);
    }
}

/// [`super::to_level`] of sixteen levels as i32 in 0..=255: for `c = min(255, x)` (NaN kept, the
/// second operand) `floor(c + 0.5)`, the sum rounded down so that it cannot round up onto the next
/// integer: that is rounding half away from zero for `c >= 0`; below 0 and NaN (`i32::MIN` from
/// the conversion) clamp to 0.
#[inline(always)]
unsafe fn levels_avx512(x: __m512) -> __m512i {
    const DOWN: i32 = _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC;
    unsafe {
        let c = _mm512_min_ps(_mm512_set1_ps(255.0), x);
        let h = _mm512_add_round_ps::<DOWN>(c, _mm512_set1_ps(0.5));
        let t = _mm512_cvt_roundps_epi32::<DOWN>(h);
        _mm512_max_epi32(t, _mm512_setzero_si512())
    }
}
