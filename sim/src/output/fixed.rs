//! Fixed-point text of `f32` values for the trajectory log: the same characters as `{:.N}`, without
//! the general formatting machinery (which works through an exact big-number algorithm and made
//! formatting most of the cost of logging a large swarm).
use std::fmt::Write;

/// Appends `x` with `decimals` digits after the point to `out`: exactly what
/// `write!(out, "{x:.decimals$}")` writes (the exact binary value rounded half to even, a `-` on
/// negative values and negative zero). Values of magnitude 2^24 or more, non-finite values and more
/// than nine decimals go through `write!`.
pub fn push_fixed(out: &mut String, x: f32, decimals: usize) {
    const POW10: [u64; 10] = [
        1,
        10,
        100,
        1_000,
        10_000,
        100_000,
        1_000_000,
        10_000_000,
        100_000_000,
        1_000_000_000,
    ];
    if !x.is_finite() || x.abs() >= 16_777_216.0 || decimals >= POW10.len() {
        let _ = write!(out, "{x:.decimals$}");
        return;
    }
    // x = mantissa * 2^-shift exactly, with an integer mantissa below 2^24.
    let bits = x.to_bits();
    let biased = ((bits >> 23) & 0xff) as i32;
    let fraction = u64::from(bits & 0x7f_ffff);
    let (mantissa, exponent) = if biased == 0 {
        (fraction, -149)
    } else {
        (fraction | 0x80_0000, biased - 150)
    };
    let scale = POW10[decimals];
    // Below 2^24 the exponent is negative or zero; the scaled mantissa is below 2^54.
    let scaled = mantissa * scale;
    let shift = (-exponent) as u32;
    let units = if shift == 0 {
        scaled
    } else if shift >= 64 {
        // Less than 2^-10 of a unit in the last place: rounds to zero (no tie is possible).
        0
    } else {
        let q = scaled >> shift;
        let r = scaled & ((1u64 << shift) - 1);
        let half = 1u64 << (shift - 1);
        q + u64::from(r > half || (r == half && q & 1 == 1))
    };
    if bits >> 31 == 1 {
        out.push('-');
    }
    push_digits(out, units / scale, 1);
    if decimals > 0 {
        out.push('.');
        push_digits(out, units % scale, decimals);
    }
}

/// Appends the decimal digits of `n`, zero-padded to at least `width` digits (at most 20, the
/// digits of `u64::MAX`).
pub fn push_digits(out: &mut String, mut n: u64, width: usize) {
    let mut buf = [b'0'; 20];
    let mut start = buf.len();
    while n > 0 {
        start -= 1;
        buf[start] = b'0' + (n % 10) as u8;
        n /= 10;
    }
    let start = start.min(buf.len() - width.clamp(1, buf.len()));
    // The buffer holds ASCII digits only.
    out.push_str(std::str::from_utf8(&buf[start..]).unwrap_or_default());
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check(x: f32, decimals: usize) {
        let mut got = String::new();
        push_fixed(&mut got, x, decimals);
        assert_eq!(
            got,
            format!("{x:.decimals$}"),
            "{x:e} with {decimals} decimals"
        );
    }

    #[test]
    fn ties_signs_and_edges_match_std() {
        for decimals in 0..=10 {
            for x in [
                0.0f32,
                -0.0,
                0.5,
                1.5,
                2.5,
                -2.5,
                0.125,
                0.375,
                -0.0625,
                0.000_005,
                0.000_015,
                1e-45,
                -1e-45,
                1.17e-38,
                16_777_215.0,
                16_777_216.0,
                -3.4e38,
                f32::NAN,
                f32::INFINITY,
                f32::NEG_INFINITY,
                std::f32::consts::PI,
            ] {
                check(x, decimals);
            }
            // Every multiple of 2^-12 in [-4, 4]: many exact ties at every number of decimals.
            for k in -16_384..=16_384 {
                check(k as f32 / 4096.0, decimals);
            }
        }
    }

    #[test]
    fn digits_match_std() {
        for n in [0u64, 1, 9, 10, 99, 100, 65_535, 4_294_967_296, u64::MAX] {
            for width in 0..=20 {
                let mut got = String::new();
                push_digits(&mut got, n, width);
                assert_eq!(got, format!("{n:0width$}"), "{n} width {width}");
            }
        }
    }

    proptest::proptest! {
        #[test]
        fn any_f32_matches_std(bits in proptest::prelude::any::<u32>(), decimals in 0usize..8) {
            let x = f32::from_bits(bits);
            let mut got = String::new();
            push_fixed(&mut got, x, decimals);
            proptest::prop_assert_eq!(got, format!("{x:.decimals$}"));
        }

        #[test]
        fn arena_sized_values_match_std(x in -20.0f32..20.0, decimals in 0usize..8) {
            let mut got = String::new();
            push_fixed(&mut got, x, decimals);
            proptest::prop_assert_eq!(got, format!("{x:.decimals$}"));
        }
    }
}
