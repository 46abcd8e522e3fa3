//! Plane-to-plane homographies: the normalised direct linear transform (Hartley's DLT on
//! centred, scaled points) and RANSAC outlier rejection around it.
use nalgebra::{Matrix3, SMatrix, SymmetricEigen, Vector3};
use serde::{Deserialize, Serialize};

/// A 3x3 projective map of the plane, row-major, normalised so that its last entry is 1 (or, when
/// that entry is near zero, so that the matrix has unit norm).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Homography(pub [[f64; 3]; 3]);

impl Homography {
    pub const IDENTITY: Homography =
        Homography([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]);

    fn matrix(&self) -> Matrix3<f64> {
        Matrix3::from_fn(|r, c| self.0[r][c])
    }

    fn from_matrix(m: &Matrix3<f64>) -> Option<Homography> {
        let scale = if m[(2, 2)].abs() > 1e-12 * m.norm() {
            m[(2, 2)]
        } else {
            m.norm()
        };
        if !(scale.is_finite() && scale != 0.0) {
            return None;
        }
        let h = Homography(std::array::from_fn(|r| {
            std::array::from_fn(|c| m[(r, c)] / scale)
        }));
        h.is_finite().then_some(h)
    }

    pub fn is_finite(&self) -> bool {
        self.0.iter().flatten().all(|v| v.is_finite())
    }

    /// The image of `p`; `None` on the line the map sends to infinity.
    pub fn apply(&self, p: [f64; 2]) -> Option<[f64; 2]> {
        let h = &self.0;
        let w = h[2][0] * p[0] + h[2][1] * p[1] + h[2][2];
        if w.abs() < 1e-12 || !w.is_finite() {
            return None;
        }
        let x = (h[0][0] * p[0] + h[0][1] * p[1] + h[0][2]) / w;
        let y = (h[1][0] * p[0] + h[1][1] * p[1] + h[1][2]) / w;
        (x.is_finite() && y.is_finite()).then_some([x, y])
    }

    /// The inverse map; `None` when singular.
    pub fn inverse(&self) -> Option<Homography> {
        Homography::from_matrix(&self.matrix().try_inverse()?)
    }

    /// `self` after `first`: p -> self(first(p)).
    pub fn compose(&self, first: &Homography) -> Option<Homography> {
        Homography::from_matrix(&(self.matrix() * first.matrix()))
    }

    /// The derivative of the map at `p` (2x2, row-major).
    pub fn jacobian(&self, p: [f64; 2]) -> Option<[[f64; 2]; 2]> {
        let h = &self.0;
        let w = h[2][0] * p[0] + h[2][1] * p[1] + h[2][2];
        let q = self.apply(p)?;
        Some(std::array::from_fn(|r| {
            std::array::from_fn(|c| (h[r][c] - q[r] * h[2][c]) / w)
        }))
    }
}

/// Moves points to their centroid and scales them to a mean distance of sqrt(2) (Hartley): the DLT
/// is then well conditioned whatever the units.
fn normaliser(points: &[[f64; 2]]) -> Matrix3<f64> {
    let n = points.len().max(1) as f64;
    let (cx, cy) = points
        .iter()
        .fold((0.0, 0.0), |(x, y), p| (x + p[0] / n, y + p[1] / n));
    let mean = points
        .iter()
        .map(|p| ((p[0] - cx).powi(2) + (p[1] - cy).powi(2)).sqrt())
        .sum::<f64>()
        / n;
    let s = if mean > 1e-300 {
        std::f64::consts::SQRT_2 / mean
    } else {
        1.0
    };
    Matrix3::new(s, 0.0, -s * cx, 0.0, s, -s * cy, 0.0, 0.0, 1.0)
}

fn transform(t: &Matrix3<f64>, p: [f64; 2]) -> [f64; 2] {
    let v = t * Vector3::new(p[0], p[1], 1.0);
    [v[0] / v[2], v[1] / v[2]]
}

/// The least-squares (algebraic) homography taking each `from[i]` to `to[i]`: at least four pairs,
/// no three of the first four on a line. `None` when the points do not determine one.
pub(crate) fn fit_dlt(from: &[[f64; 2]], to: &[[f64; 2]]) -> Option<Homography> {
    if from.len() != to.len() || from.len() < 4 {
        return None;
    }
    let (tf, tt) = (normaliser(from), normaliser(to));
    // A^T A accumulated pair by pair (9x9): its eigenvector of the smallest eigenvalue is the
    // homography; this also works for exactly four pairs, where A itself is 8x9.
    let mut ata = SMatrix::<f64, 9, 9>::zeros();
    for (p, q) in from.iter().zip(to) {
        let [x, y] = transform(&tf, *p);
        let [u, v] = transform(&tt, *q);
        let rows = [
            [-x, -y, -1.0, 0.0, 0.0, 0.0, u * x, u * y, u],
            [0.0, 0.0, 0.0, -x, -y, -1.0, v * x, v * y, v],
        ];
        for row in rows {
            let r = SMatrix::<f64, 1, 9>::from_row_slice(&row);
            ata += r.transpose() * r;
        }
    }
    let eig = SymmetricEigen::new(ata);
    let (k, smallest) = eig
        .eigenvalues
        .iter()
        .enumerate()
        .min_by(|a, b| a.1.total_cmp(b.1))?;
    let second = eig
        .eigenvalues
        .iter()
        .enumerate()
        .filter(|(j, _)| *j != k)
        .map(|(_, v)| *v)
        .fold(f64::INFINITY, f64::min);
    // A second (near) null vector: the points are degenerate (collinear, repeated).
    if !(second > 1e-10 && *smallest < 0.5 * second) {
        return None;
    }
    let h = eig.eigenvectors.column(k);
    let hn = Matrix3::from_fn(|r, c| h[3 * r + c]);
    let m = tt.try_inverse()? * hn * tf;
    Homography::from_matrix(&m)
}

/// Distance from `h(from)` to `to`, in `to`'s units (infinite where the map is undefined).
pub(crate) fn residual(h: &Homography, from: [f64; 2], to: [f64; 2]) -> f64 {
    h.apply(from)
        .map(|p| ((p[0] - to[0]).powi(2) + (p[1] - to[1]).powi(2)).sqrt())
        .unwrap_or(f64::INFINITY)
}

/// A robust fit and which pairs it kept.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct RobustFit {
    pub homography: Homography,
    /// Per pair: kept (an inlier) or rejected.
    pub inliers: Vec<bool>,
    /// Root mean square residual over the inliers, in `to`'s units.
    pub rms: f64,
}

/// RANSAC: homographies through random four-pair samples, the one that explains the most pairs
/// within `threshold` (in `to`'s units) wins and is refitted on them (twice, as the inlier set
/// settles). Deterministic for a given `seed`.
pub(crate) fn fit_ransac(
    from: &[[f64; 2]],
    to: &[[f64; 2]],
    threshold: f64,
    iterations: usize,
    seed: u64,
) -> Option<RobustFit> {
    let n = from.len();
    if n != to.len() || n < 4 || threshold.is_nan() || threshold <= 0.0 {
        return None;
    }
    let count = |h: &Homography| -> (usize, f64) {
        from.iter().zip(to).fold((0, 0.0), |(k, s), (p, q)| {
            let r = residual(h, *p, *q);
            if r <= threshold {
                (k + 1, s + r * r)
            } else {
                (k, s)
            }
        })
    };
    let mut best: Option<(Homography, usize, f64)> = fit_dlt(from, to).map(|h| {
        let (k, s) = count(&h);
        (h, k, s)
    });
    let mut state = seed ^ 0x9E37_79B9_7F4A_7C15;
    let mut next = |bound: usize| {
        // splitmix64: enough for choosing samples.
        state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) % bound as u64) as usize
    };
    for _ in 0..iterations {
        let mut pick = [usize::MAX; 4];
        for k in 0..4 {
            let mut j = next(n);
            while pick[..k].contains(&j) {
                j = next(n);
            }
            pick[k] = j;
        }
        let f: Vec<_> = pick.iter().map(|&j| from[j]).collect();
        let t: Vec<_> = pick.iter().map(|&j| to[j]).collect();
        let Some(h) = fit_dlt(&f, &t) else { continue };
        let (k, s) = count(&h);
        if best
            .as_ref()
            .is_none_or(|(_, bk, bs)| k > *bk || (k == *bk && s < *bs))
        {
            best = Some((h, k, s));
        }
    }
    let (mut h, _, _) = best?;
    let mut inliers = vec![false; n];
    for _ in 0..3 {
        for (flag, (p, q)) in inliers.iter_mut().zip(from.iter().zip(to)) {
            *flag = residual(&h, *p, *q) <= threshold;
        }
        let f: Vec<_> = (0..n).filter(|&i| inliers[i]).map(|i| from[i]).collect();
        let t: Vec<_> = (0..n).filter(|&i| inliers[i]).map(|i| to[i]).collect();
        h = fit_dlt(&f, &t)?;
    }
    for (flag, (p, q)) in inliers.iter_mut().zip(from.iter().zip(to)) {
        *flag = residual(&h, *p, *q) <= threshold;
    }
    let kept = inliers.iter().filter(|&&k| k).count();
    if kept < 4 {
        return None;
    }
    let ss: f64 = (0..n)
        .filter(|&i| inliers[i])
        .map(|i| residual(&h, from[i], to[i]).powi(2))
        .sum();
    Some(RobustFit {
        homography: h,
        inliers,
        rms: (ss / kept as f64).sqrt(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn truth() -> Homography {
        Homography([[2.1, 0.05, 30.0], [-0.03, 1.9, 12.0], [1e-5, -2e-5, 1.0]])
    }

    #[test]
    fn four_exact_pairs_give_the_map_back() {
        let h = truth();
        let from = [[0.0, 0.0], [100.0, 0.0], [100.0, 80.0], [0.0, 80.0]];
        let to: Vec<_> = from.iter().map(|p| h.apply(*p).unwrap()).collect();
        let f = fit_dlt(&from, &to).unwrap();
        for p in [[50.0, 40.0], [-20.0, 130.0]] {
            let (a, b) = (f.apply(p).unwrap(), h.apply(p).unwrap());
            assert!((a[0] - b[0]).abs() < 1e-6 && (a[1] - b[1]).abs() < 1e-6);
        }
        let back = f.inverse().unwrap().compose(&f).unwrap();
        assert!((back.0[0][0] - 1.0).abs() < 1e-9 && back.0[0][1].abs() < 1e-9);
    }

    #[test]
    fn collinear_points_are_refused() {
        let from = [[0.0, 0.0], [1.0, 1.0], [2.0, 2.0], [3.0, 3.0], [4.0, 4.0]];
        assert!(fit_dlt(&from, &from).is_none());
    }

    #[test]
    fn ransac_drops_gross_outliers() {
        let h = truth();
        let mut from = Vec::new();
        for i in 0..6 {
            for j in 0..5 {
                from.push([i as f64 * 20.0, j as f64 * 15.0]);
            }
        }
        let mut to: Vec<_> = from.iter().map(|p| h.apply(*p).unwrap()).collect();
        to[3][0] += 40.0;
        to[17][1] -= 25.0;
        let plain = fit_dlt(&from, &to).unwrap();
        let fit = fit_ransac(&from, &to, 1.0, 200, 7).unwrap();
        assert!(!fit.inliers[3] && !fit.inliers[17]);
        assert_eq!(fit.inliers.iter().filter(|&&k| k).count(), 28);
        assert!(fit.rms < 1e-6, "{}", fit.rms);
        assert!(residual(&plain, from[0], h.apply(from[0]).unwrap()) > 0.1);
    }

    #[test]
    fn jacobian_matches_finite_differences() {
        let h = truth();
        let p = [40.0, 30.0];
        let j = h.jacobian(p).unwrap();
        let e = 1e-4;
        let a = h.apply(p).unwrap();
        let bx = h.apply([p[0] + e, p[1]]).unwrap();
        let by = h.apply([p[0], p[1] + e]).unwrap();
        assert!(((bx[0] - a[0]) / e - j[0][0]).abs() < 1e-4);
        assert!(((by[1] - a[1]) / e - j[1][1]).abs() < 1e-4);
        assert!(((by[0] - a[0]) / e - j[0][1]).abs() < 1e-4);
    }
}
