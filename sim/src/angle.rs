//! Angles wrapped into one turn: the simulator's headings, the tracker's and the behaviours' all go
//! through these, so that a heading is wrapped the same way, bit for bit, wherever it is.
use std::f32::consts::{PI, TAU};

/// `a.rem_euclid(TAU)`, bit for bit, without the `fmodf` call for angles within two turns of zero
/// (every heading a step produces): there the remainder is one exact subtraction or addition.
#[inline]
pub fn rem_tau(a: f32) -> f32 {
    if (0.0..TAU).contains(&a) {
        a
    } else if (TAU..2.0 * TAU).contains(&a) {
        // Exact (Sterbenz: TAU <= a <= 2 TAU), so what `fmodf` gives.
        a - TAU
    } else if a > -TAU && a < 0.0 {
        // `fmodf` leaves |a| < TAU as it is; `rem_euclid` then adds TAU.
        a + TAU
    } else {
        a.rem_euclid(TAU)
    }
}

/// `a` wrapped into `(-pi, pi]`; a non-finite angle gives 0.
#[inline]
pub fn wrap_pi(a: f32) -> f32 {
    if !a.is_finite() {
        return 0.0;
    }
    let w = rem_tau(a);
    if w > PI { w - TAU } else { w }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The shortcut gives `rem_euclid`'s bits over the angles it takes and around its edges.
    #[test]
    fn rem_tau_is_rem_euclid() {
        let mut a = -3.0 * TAU;
        while a < 3.0 * TAU {
            for x in [a, f32::from_bits(a.to_bits() + 1), -a] {
                assert_eq!(rem_tau(x).to_bits(), x.rem_euclid(TAU).to_bits(), "at {x}");
            }
            a += 1.0e-3;
        }
        for x in [
            0.0,
            -0.0,
            TAU,
            -TAU,
            2.0 * TAU,
            -2.0 * TAU,
            PI,
            -PI,
            1e-30,
            -1e-30,
            1e9,
            -1e9,
        ] {
            let near = [
                x,
                f32::from_bits(x.to_bits().wrapping_sub(1)),
                f32::from_bits(x.to_bits() + 1),
            ];
            for y in near.into_iter().filter(|y| y.is_finite()) {
                assert_eq!(rem_tau(y).to_bits(), y.rem_euclid(TAU).to_bits(), "at {y}");
            }
        }
    }

    #[test]
    fn wrap_pi_keeps_the_half_open_range() {
        assert_eq!(wrap_pi(PI), PI);
        assert_eq!(wrap_pi(-PI), PI);
        assert!((wrap_pi(3.0 * PI / 2.0) + PI / 2.0).abs() < 1e-6);
        assert!((wrap_pi(-7.0) - (-7.0 + TAU)).abs() < 1e-6);
        assert_eq!(wrap_pi(0.25), 0.25);
        assert_eq!(wrap_pi(f32::NAN), 0.0);
        assert_eq!(wrap_pi(f32::INFINITY), 0.0);
    }
}
