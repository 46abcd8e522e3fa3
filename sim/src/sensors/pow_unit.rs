//! `x^y` for `x` in [0, 1] and `y > 0` (the colour sensor's calibrated inverse, `light^(1 / gamma)`)
//! in plain IEEE f32 arithmetic, branch-free, so that a loop over a robot's twelve channels
//! vectorises: libm's `powf` is a call per value and was about a tenth of a batched world's step.
//!
//! `x^y = 2^(y log2 x)`: `log2` from the exponent bits and an odd series of `atanh` on the mantissa,
//! `2^z` from a rounded integer part (exponent bits) and a degree-7 polynomial on the fraction.
//! Relative error under `4e-7 + 1e-7 |y log2 x|` (a few f32 ulps where it matters: the exponent `z`
//! carries an f32 rounding of its own; tested against f64 `powf`). The same operations on every
//! machine (no fused multiply-add), so results do not depend on the CPU.

/// `2 / ln 2`: `log2(m) = (2 / ln 2) atanh((m - 1) / (m + 1))`.
const LOG2_C1: f32 = std::f64::consts::LOG2_E as f32 * 2.0;
/// `ln 2`.
const LN2: f64 = std::f64::consts::LN_2;
/// Adding and subtracting `1.5 * 2^23` rounds an f32 of magnitude below `2^22` to an integer.
const ROUND_MAGIC: f32 = 12_582_912.0;

/// `x^y` for `x` in [0, 1] (0 for 0, NaN, negative or subnormal `x`; exactly 1 for `x = 1`) and finite
/// `y > 0`. Results below `2^-126` flush to 0.
#[inline(always)]
pub fn pow_unit(x: f32, y: f32) -> f32 {
    let normal = x >= f32::MIN_POSITIVE;
    let xs = if normal { x } else { 1.0 };
    // log2 x = e + log2 m with m in [sqrt(1/2), sqrt(2)): shift the bits by those of sqrt(1/2) so that
    // the exponent field gives e directly.
    let bits = xs.to_bits();
    let e = (bits.wrapping_sub(0x3f35_04f3) as i32) >> 23;
    let m = f32::from_bits(bits.wrapping_sub((e << 23) as u32));
    let t = (m - 1.0) / (m + 1.0);
    let t2 = t * t;
    // atanh(t) = t + t^3/3 + ...; |t| <= 0.1716, so the t^11 term is below 1e-9.
    let series = LOG2_C1
        + t2 * (LOG2_C1 / 3.0 + t2 * (LOG2_C1 / 5.0 + t2 * (LOG2_C1 / 7.0 + t2 * (LOG2_C1 / 9.0))));
    let z = y * (e as f32 + t * series);
    // 2^z, z <= 0 here (x <= 1): 2^n times 2^f with n = round(z), f in [-1/2, 1/2].
    let underflow = z < -126.0 || z.is_nan();
    let zc = if underflow { 0.0 } else { z.min(0.0) };
    let n = (zc + ROUND_MAGIC) - ROUND_MAGIC;
    let f = zc - n;
    let p = 1.0
        + f * (C[1] + f * (C[2] + f * (C[3] + f * (C[4] + f * (C[5] + f * (C[6] + f * C[7]))))));
    // SAFETY: `n` is an integer in [-126, 0] (NaN went to 0 above).
    let n = unsafe { n.to_int_unchecked::<i32>() };
    let scale = f32::from_bits(((n + 127) << 23) as u32);
    if normal && !underflow { p * scale } else { 0.0 }
}

/// Taylor coefficients of `2^f = e^(f ln 2)`: `C[k] = (ln 2)^k / k!` (the series to `f^7` is within
/// 6e-9 on [-1/2, 1/2]).
const C: [f32; 8] = [
    1.0,
    LN2 as f32,
    (LN2 * LN2 / 2.0) as f32,
    (LN2 * LN2 * LN2 / 6.0) as f32,
    (LN2 * LN2 * LN2 * LN2 / 24.0) as f32,
    (LN2 * LN2 * LN2 * LN2 * LN2 / 120.0) as f32,
    (LN2 * LN2 * LN2 * LN2 * LN2 * LN2 / 720.0) as f32,
    (LN2 * LN2 * LN2 * LN2 * LN2 * LN2 * LN2 / 5040.0) as f32,
];

#[cfg(test)]
mod tests {
    use super::*;

    /// Relative error of `pow_unit` against f64 `powf` (within the module's bound), over every 97th f32 in (0, 1] and the
    /// exponents of the plausible display curves (1/gamma for gamma in 0.5..3) and beyond.
    #[test]
    fn matches_f64_pow() {
        let mut worst = 0.0f64;
        for y in [0.3f32, 1.0 / 2.2, 1.0 / 1.8, 0.5, 1.0, 1.0 / 0.6, 2.0, 2.2] {
            let mut bits = f32::MIN_POSITIVE.to_bits();
            while bits <= 1.0f32.to_bits() {
                let x = f32::from_bits(bits);
                let want = (x as f64).powf(y as f64);
                let got = pow_unit(x, y) as f64;
                if want >= f32::MIN_POSITIVE as f64 * 4.0 {
                    let rel = (got - want).abs() / want;
                    let tolerance = 4e-7 + 1e-7 * (y as f64 * (x as f64).log2()).abs();
                    worst = worst.max(rel / tolerance);
                    assert!(rel < tolerance, "{x}^{y}: {got} vs {want} (rel {rel:e})");
                }
                bits += 97;
            }
        }
        assert!(worst > 0.0, "compared nothing");
        eprintln!("worst error {worst:.2} of the tolerance");
    }

    #[test]
    fn edges() {
        for y in [0.1f32, 1.0 / 2.2, 1.0, 7.0] {
            assert_eq!(pow_unit(1.0, y), 1.0);
            assert_eq!(pow_unit(0.0, y), 0.0);
            assert_eq!(pow_unit(-0.5, y), 0.0);
            assert_eq!(pow_unit(f32::NAN, y), 0.0);
            assert_eq!(pow_unit(1e-40, y), 0.0);
        }
        // 2^-200 underflows f32: flushed to 0, never garbage.
        assert_eq!(pow_unit(2f32.powi(-100), 2.0), 0.0);
        assert_eq!(pow_unit(0.5, 1.0), 0.5);
    }

    /// The inverse of the transfer curve is monotonic, as the calibration needs.
    #[test]
    fn monotonic() {
        let y = 1.0 / 2.2;
        let mut last = 0.0;
        for k in 0..=100_000 {
            let v = pow_unit(k as f32 / 100_000.0, y);
            assert!(v >= last, "at {k}: {v} < {last}");
            last = v;
        }
    }
}
