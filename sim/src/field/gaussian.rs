//! Gaussian-source model, eq. (5).
#![allow(clippy::neg_cmp_op_on_partial_ord)] // NaN-aware test
use glam::Vec2;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GaussianSource {
    /// Scale factor K.
    pub k: f32,
    /// m.
    pub sigma_x: f32,
    /// m.
    pub sigma_y: f32,
    /// Correlation, |rho| < 1.
    pub rho: f32,
    /// Evaporation time e, s.
    pub evaporation: f32,
    /// (mu_x, mu_y), m.
    pub centre: Vec2,
    /// Time the source's clock started, s; zero before it.
    pub start: f32,
}

impl GaussianSource {
    /// Eq. (5) at `p` and absolute time `t`.
    ///
    /// The clock `t - start` is the `t` of eq. (5); the value is 0 before `start`.
    pub fn value_at(&self, p: Vec2, t: f32) -> f32 {
        self.at_time(t).map_or(0.0, |s| s.value_at(p))
    }

    /// The source frozen at time `t` (its time-dependent factors computed once), or `None` before its
    /// start.
    #[inline]
    pub fn at_time(&self, t: f32) -> Option<FrozenSource> {
        if !(t >= self.start) {
            return None;
        }
        let tau = (t - self.start) as f64;
        let (sx, sy, rho) = (self.sigma_x as f64, self.sigma_y as f64, self.rho as f64);
        let one_m_rho2 = 1.0 - rho * rho;
        let e = self.evaporation as f64;
        let decay = if e.is_infinite() {
            1.0
        } else {
            (-tau / e).exp()
        };
        let norm = self.k as f64 / (2.0 * std::f64::consts::PI * sx * sy * one_m_rho2.sqrt());
        // Reciprocals once per source: the exponent at a point is then multiplications only (the f64
        // rounding differs from dividing by a few ulps, far below what the f32 result can show).
        Some(FrozenSource {
            amplitude: norm * decay,
            centre: self.centre,
            qxx: 1.0 / (sx * sx),
            qyy: 1.0 / (sy * sy),
            qxy: 2.0 * rho / (sx * sy),
            scale: -1.0 / (2.0 * one_m_rho2),
        })
    }
}

/// A source at one instant: eq. (5) as a function of position only.
#[derive(Clone, Copy, Debug)]
pub struct FrozenSource {
    amplitude: f64,
    centre: Vec2,
    /// The quadratic form of eq. (5): `q = qxx dx^2 + qyy dy^2 - qxy dx dy`.
    qxx: f64,
    qyy: f64,
    qxy: f64,
    /// `-1 / (2 (1 - rho^2))`: the exponent is `scale q`.
    scale: f64,
}

impl FrozenSource {
    #[inline]
    pub fn value_at(&self, p: Vec2) -> f32 {
        (self.amplitude * self.exponent(p).exp()) as f32
    }

    /// The exponent of eq. (5) at `p`: `-q / (2 (1 - rho^2))`.
    #[inline]
    fn exponent(&self, p: Vec2) -> f64 {
        self.exponent_xy(p.x, p.y)
    }

    #[inline(always)]
    fn exponent_xy(&self, px: f32, py: f32) -> f64 {
        let dx = (px - self.centre.x) as f64;
        let dy = (py - self.centre.y) as f64;
        (dx * dx * self.qxx + dy * dy * self.qyy - dx * dy * self.qxy) * self.scale
    }

    /// Adds the source's values at the points `(xs[k], ys[k])` to `out[k]`. The points come in groups of
    /// `group` consecutive points close together (a sensor's footprint) that share one `exp`:
    /// `exp(x0 + e) = exp(x0) (1 + e + ... + e^6 / 720)` for `|e| < TAYLOR_MAX`, whose relative error
    /// (< 2e-15) is far below f32's resolution, so the f32 values are those of
    /// [`FrozenSource::value_at`]; farther points take their own `exp`. Structure of arrays, and the
    /// exponents in a fixed-size buffer, so that the arithmetic over the points vectorises.
    #[inline(always)]
    pub fn add_values_soa(&self, xs: &[f32], ys: &[f32], group: usize, out: &mut [f32]) {
        let n = xs.len().min(ys.len()).min(out.len());
        let group = group.clamp(1, MAX_POINTS);
        let chunk = MAX_POINTS / group * group;
        let (xs, ys, out) = (&xs[..n], &ys[..n], &mut out[..n]);
        for ((xs, ys), out) in xs
            .chunks(chunk)
            .zip(ys.chunks(chunk))
            .zip(out.chunks_mut(chunk))
        {
            self.add_values_chunk(xs, ys, group, out);
        }
    }

    /// [`FrozenSource::add_values_soa`] for at most [`MAX_POINTS`] points.
    #[inline(always)]
    fn add_values_chunk(&self, xs: &[f32], ys: &[f32], group: usize, out: &mut [f32]) {
        let n = xs.len();
        let mut exponent = [0f64; MAX_POINTS];
        for ((x, &px), &py) in exponent[..n].iter_mut().zip(xs).zip(ys) {
            *x = self.exponent_xy(px, py);
        }
        for (exponent, out) in exponent[..n].chunks(group).zip(out.chunks_mut(group)) {
            let x0 = exponent[0];
            let e0 = x0.exp();
            let spread = exponent.iter().fold(0f64, |m, x| m.max((x - x0).abs()));
            if spread < TAYLOR_MAX {
                for (o, &x) in out.iter_mut().zip(exponent) {
                    *o += (self.amplitude * (e0 * exp_series(x - x0))) as f32;
                }
            } else {
                for (o, &x) in out.iter_mut().zip(exponent) {
                    let e = x - x0;
                    let v = if e.abs() < TAYLOR_MAX {
                        e0 * exp_series(e)
                    } else {
                        x.exp()
                    };
                    *o += (self.amplitude * v) as f32;
                }
            }
        }
    }
}

/// Points evaluated together by [`FrozenSource::add_values_soa`] (four sensors' footprints fit).
pub const MAX_POINTS: usize = 64;

/// Offsets of the exponent below which [`exp_series`] stands in for `exp`.
const TAYLOR_MAX: f64 = 0.03;

/// `exp(e)` for `|e| < TAYLOR_MAX` to 6th order: Horner form with the factorials' reciprocals
/// (multiplications, no divisions); relative error < 2e-15.
#[inline(always)]
fn exp_series(e: f64) -> f64 {
    1.0 + e
        * (1.0
            + e * 0.5
                * (1.0
                    + e * (1.0 / 3.0)
                        * (1.0 + e * 0.25 * (1.0 + e * 0.2 * (1.0 + e * (1.0 / 6.0))))))
}

/// The sum of frozen sources at many points (the same values as [`GaussianField::values_at`] for the
/// field's sources frozen by [`GaussianField::freeze_into`]): sensing freezes them once per step
/// instead of once per sensor.
pub fn frozen_values_at(sources: &[FrozenSource], points: &[Vec2], out: &mut [f32]) {
    out.fill(0.0);
    let (mut xs, mut ys) = ([0f32; MAX_POINTS], [0f32; MAX_POINTS]);
    for (points, out) in points.chunks(MAX_POINTS).zip(out.chunks_mut(MAX_POINTS)) {
        let n = points.len();
        for ((x, y), p) in xs.iter_mut().zip(&mut ys).zip(points) {
            (*x, *y) = (p.x, p.y);
        }
        for s in sources {
            s.add_values_soa(&xs[..n], &ys[..n], n, out);
        }
    }
}

/// A set of Gaussian sources summed, with its own clock.
#[derive(Clone, Debug, Default)]
pub struct GaussianField {
    pub sources: Vec<GaussianSource>,
    pub time: f32,
}

impl GaussianField {
    pub fn value_at(&self, p: Vec2) -> f32 {
        self.sources.iter().map(|s| s.value_at(p, self.time)).sum()
    }
    /// The field at many points: `out[k]` = the value at `points[k]` (the sum of
    /// [`GaussianField::value_at`], with each source's time factors computed once and nearby points
    /// sharing an `exp`, see [`FrozenSource::add_values_soa`]).
    pub fn values_at(&self, points: &[Vec2], out: &mut [f32]) {
        let mut frozen = Vec::with_capacity(self.sources.len());
        self.freeze_into(&mut frozen);
        frozen_values_at(&frozen, points, out);
    }
    /// Appends every source that has started, frozen at the field's time, to `out`: what
    /// [`frozen_values_at`] needs to give the values of [`GaussianField::values_at`].
    pub fn freeze_into(&self, out: &mut Vec<FrozenSource>) {
        out.extend(self.sources.iter().filter_map(|s| s.at_time(self.time)));
    }
    pub fn step(&mut self, dt: f32) {
        self.time += dt;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Footprints that share one `exp` read the same f32 values as point-by-point evaluation, for
    /// wide and narrow, round and skewed sources, near and far from the centre.
    #[test]
    fn shared_exp_footprints_equal_pointwise_values() {
        let mut compared = 0;
        for (sigma, rho) in [((0.4, 0.4), 0.0), ((0.05, 0.12), 0.6), ((0.6, 0.2), -0.45)] {
            let field = GaussianField {
                sources: vec![GaussianSource {
                    k: 1.7,
                    sigma_x: sigma.0,
                    sigma_y: sigma.1,
                    rho,
                    evaporation: 5.0,
                    centre: Vec2::new(0.7, 0.4),
                    start: 0.5,
                }],
                time: 2.25,
            };
            for i in 0..60 {
                for j in 0..30 {
                    let c = Vec2::new(i as f32 * 0.024, j as f32 * 0.027);
                    let points: Vec<Vec2> = (0..9)
                        .map(|k| c + 0.00105 * Vec2::from_angle(k as f32 * 0.8))
                        .collect();
                    let mut got = vec![0.0; 9];
                    field.values_at(&points, &mut got);
                    for (p, g) in points.iter().zip(&got) {
                        assert_eq!(*g, field.value_at(*p), "sigma {sigma:?} rho {rho} at {p}");
                        compared += usize::from(*g > 1e-3);
                    }
                }
            }
        }
        assert!(
            compared > 5_000,
            "only {compared} non-negligible values compared"
        );
    }
}
