//! Injection kernels: the shape a deposit takes around a point.
use serde::{Deserialize, Serialize};

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "shape", rename_all = "snake_case", deny_unknown_fields)]
pub enum Kernel {
    /// 1 inside `radius`, 0 outside.
    Disc { radius: f32 },
    /// 1 at the centre, falling linearly to 0 at `radius`.
    Cone { radius: f32 },
    /// exp(-r^2 / 2 sigma^2), cut at 3 sigma.
    Gaussian { sigma: f32 },
}

impl Kernel {
    /// Weight at `distance` (m) from the deposit point; 0 beyond [`Kernel::support`].
    pub fn weight(&self, distance: f32) -> f32 {
        let d = distance.abs();
        match *self {
            Kernel::Disc { radius } => {
                if d <= radius {
                    1.0
                } else {
                    0.0
                }
            }
            Kernel::Cone { radius } => {
                if d < radius {
                    1.0 - d / radius
                } else {
                    0.0
                }
            }
            Kernel::Gaussian { sigma } => {
                if d <= 3.0 * sigma && sigma > 0.0 {
                    (-d * d / (2.0 * sigma * sigma)).exp()
                } else if d == 0.0 {
                    1.0
                } else {
                    0.0
                }
            }
        }
    }
    /// Distance beyond which the weight is zero, m.
    pub fn support(&self) -> f32 {
        match *self {
            Kernel::Disc { radius } | Kernel::Cone { radius } => radius,
            Kernel::Gaussian { sigma } => 3.0 * sigma,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shapes() {
        let d = Kernel::Disc { radius: 0.1 };
        assert_eq!(
            (d.weight(0.0), d.weight(0.1), d.weight(0.1001)),
            (1.0, 1.0, 0.0)
        );
        assert_eq!(d.support(), 0.1);
        let c = Kernel::Cone { radius: 0.2 };
        assert_eq!(c.weight(0.0), 1.0);
        assert!((c.weight(0.1) - 0.5).abs() < 1e-6);
        assert_eq!(c.weight(0.2), 0.0);
        let g = Kernel::Gaussian { sigma: 0.01 };
        assert!((g.support() - 0.03).abs() < 1e-9);
        assert!((g.weight(0.01) - (-0.5f32).exp()).abs() < 1e-6);
        assert!(g.weight(0.0299) > 0.0);
        assert_eq!(g.weight(0.0301), 0.0);
    }
}
