//! Gaussian-source model, eq. (5).
#![allow(clippy::neg_cmp_op_on_partial_ord)] // NaN-aware test
use super::NearbyPoints;
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
        let (qxx, qyy, qxy) = (1.0 / (sx * sx), 1.0 / (sy * sy), 2.0 * rho / (sx * sy));
        let scale = -1.0 / (2.0 * one_m_rho2);
        Some(FrozenSource {
            amplitude: norm * decay,
            centre: self.centre,
            qxx,
            qyy,
            qxy,
            scale,
            form: [qxx * scale, qyy * scale, qxy * scale].map(|k| k as f32),
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
    /// `scale * (qxx, qyy, qxy)` in f32: the exponent's change over a group of nearby points.
    form: [f32; 3],
}

impl FrozenSource {
    #[inline]
    pub fn value_at(&self, p: Vec2) -> f32 {
        (self.amplitude * self.exponent(p).exp()) as f32
    }

    /// The value at `p` and its gradient (per m), analytically: `grad = value * grad(exponent)`.
    pub fn value_and_gradient(&self, p: Vec2) -> (f32, Vec2) {
        let (dx, dy) = ((p.x - self.centre.x) as f64, (p.y - self.centre.y) as f64);
        let value = self.amplitude * self.exponent(p).exp();
        let gx = (2.0 * self.qxx * dx - self.qxy * dy) * self.scale;
        let gy = (2.0 * self.qyy * dy - self.qxy * dx) * self.scale;
        (
            value as f32,
            Vec2::new((value * gx) as f32, (value * gy) as f32),
        )
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
    /// `group` consecutive points close together (a robot's four sensor footprints, at most
    /// [`MAX_GROUP`]) that share one `exp`: see [`FrozenSource::add_values_near`].
    #[inline(always)]
    pub fn add_values_soa(&self, xs: &[f32], ys: &[f32], group: usize, out: &mut [f32]) {
        let n = xs.len().min(ys.len()).min(out.len());
        let group = group.clamp(1, MAX_GROUP);
        let (xs, ys, out) = (&xs[..n], &ys[..n], &mut out[..n]);
        for ((xs, ys), out) in xs
            .chunks(group)
            .zip(ys.chunks(group))
            .zip(out.chunks_mut(group))
        {
            let near = NearbyPoints::<MAX_GROUP>::new(xs, ys);
            let mut values = [0f32; MAX_GROUP];
            self.add_values_near(&near, xs, ys, &mut values);
            for (o, v) in out.iter_mut().zip(values) {
                *o += v;
            }
        }
    }

    /// Adds the source's values at a group of points close together (`near`, made from `xs`, `ys`)
    /// to `out`, with one `exp` at the group's centroid `c`: the exponent `x` is quadratic, so its
    /// change to a point `p = c + e` is
    /// `d = e_x (2 kxx dx0 - kxy dy0) + e_y (2 kyy dy0 - kxy dx0) + kxx e_x^2 + kyy e_y^2 - kxy e_x e_y`
    /// (`(dx0, dy0) = c - centre`), computed in f32, and `exp(x(p)) = exp(x(c)) exp(d)` with `exp(d)`
    /// by its series. A bound on the magnitudes of `d`'s terms over the whole group (from the largest
    /// offsets) picks the series: 5th order up to 0.1 (error below 1.4e-9), 7th up to [`SERIES_MAX`]
    /// (4e-10); f32's rounding of `d` is within a few ulps of that bound. A group beyond it (a narrow
    /// source) takes [`FrozenSource::add_values_group`]. The values agree with
    /// [`FrozenSource::value_at`] to a few f32 ulps (tested), exactly for a group of one point.
    /// Structure of arrays over all `G` slots (a slot past the group's points reads as the centroid;
    /// `out[k]` for `k >= xs.len()` is not meaningful): the loops vectorise and unroll.
    #[inline(always)]
    pub fn add_values_near<const G: usize>(
        &self,
        near: &NearbyPoints<G>,
        xs: &[f32],
        ys: &[f32],
        out: &mut [f32; G],
    ) {
        let (cx, cy) = near.centroid;
        let (dx0, dy0) = (cx - self.centre.x, cy - self.centre.y);
        let [kxx, kyy, kxy] = self.form;
        let (mx, my) = near.max_offset;
        let bound = kxx.abs() * mx * (2.0 * dx0.abs() + mx)
            + kyy.abs() * my * (2.0 * dy0.abs() + my)
            + kxy.abs() * (dx0.abs() * my + mx * dy0.abs() + mx * my);
        if !(bound <= SERIES_MAX) {
            let n = near.len;
            self.add_values_group(near.centroid, &xs[..n], &ys[..n], &mut out[..n]);
            return;
        }
        let base = (self.amplitude * self.exponent_xy(cx, cy).exp()) as f32;
        let (a, b) = (kxx * (dx0 + dx0) - kxy * dy0, kyy * (dy0 + dy0) - kxy * dx0);
        let (ex, ey, exx, eyy, exy) = (&near.ex, &near.ey, &near.exx, &near.eyy, &near.exy);
        let change = |k: usize| a * ex[k] + b * ey[k] + kxx * exx[k] + kyy * eyy[k] - kxy * exy[k];
        // Uncorrelated (`kxy = 0`, the usual source): the last term is a zero whose subtraction
        // changes at most the sign of a zero change, after which the series is exactly 1 either way.
        // (Every `exy` is finite here: with `kxy = 0` the bound is finite only if the largest
        // offsets' product, which bounds them, is.)
        let plain = |k: usize| a * ex[k] + b * ey[k] + kxx * exx[k] + kyy * eyy[k];
        // The four loops are written out (by `add!`): one generic helper function for them cost 69
        // more instructions per agent-step (`bash benches/instructions.sh`, discs: 7,013 against 6,944).
        macro_rules! add {
            ($series:ident, $change:ident) => {
                out.iter_mut()
                    .enumerate()
                    .for_each(|(k, o)| *o += base * $series($change(k)))
            };
        }
        match (bound <= 0.1, kxy == 0.0) {
            (true, false) => add!(exp_series5, change),
            (true, true) => add!(exp_series5, plain),
            (false, false) => add!(exp_series, change),
            (false, true) => add!(exp_series, plain),
        }
    }

    /// One group of points around `centroid` with a per-point check: the series where a point's own
    /// change of the exponent is small, its own f64 `exp` elsewhere (narrow sources). Out of line:
    /// inlined, its offsets from the centroid were hoisted to the start of every footprint
    /// evaluation, narrow source or not.
    #[cold]
    #[inline(never)]
    fn add_values_group(&self, centroid: (f32, f32), xs: &[f32], ys: &[f32], out: &mut [f32]) {
        let (cx, cy) = centroid;
        let base = (self.amplitude * self.exponent_xy(cx, cy).exp()) as f32;
        let (dx0, dy0) = (cx - self.centre.x, cy - self.centre.y);
        let [kxx, kyy, kxy] = self.form;
        // The change `d` and the sum of its terms' magnitudes: `d` is accurate to f32's resolution of
        // that sum, so a point is near when the sum (not only `d`, whose terms may cancel) is small.
        let change = |px: f32, py: f32| {
            let (ex, ey) = (px - cx, py - cy);
            // x(c + e) - x(c) = kxx ex (2 dx0 + ex) + kyy ey (2 dy0 + ey) - kxy (dx0 ey + ex dy0 + ex ey)
            let (tx, ty) = (kxx * ex * (dx0 + dx0 + ex), kyy * ey * (dy0 + dy0 + ey));
            let txy = kxy * (dx0 * ey + ex * dy0 + ex * ey);
            (tx + ty - txy, tx.abs() + ty.abs() + txy.abs())
        };
        // Branch-free (a mask on the bits, a count of the far points) so that the loop vectorises.
        let mut far = 0u32;
        for ((o, &px), &py) in out.iter_mut().zip(xs).zip(ys) {
            let (d, size) = change(px, py);
            let near = size <= SERIES_MAX;
            far += u32::from(!near);
            let mask = 0u32.wrapping_sub(u32::from(near));
            *o += f32::from_bits((base * exp_series(d)).to_bits() & mask);
        }
        if far > 0 {
            for ((o, &px), &py) in out.iter_mut().zip(xs).zip(ys) {
                if !(change(px, py).1 <= SERIES_MAX) {
                    *o += (self.amplitude * self.exponent_xy(px, py).exp()) as f32;
                }
            }
        }
    }
}

/// The most points that share one `exp` per source (a robot's 36 footprint samples fit).
pub const MAX_GROUP: usize = 64;

/// Changes of the exponent (the sum of its terms' magnitudes) up to which [`exp_series`] stands in
/// for `exp`: the exponent of a source of sigma 0.4 m changes by at most ~0.16 over a robot's
/// footprints (1.6 cm from their centre) 1.6 m away; narrower sources take their own `exp` per point.
const SERIES_MAX: f32 = 0.25;

/// `exp(d)` for `|d| <= SERIES_MAX` to 7th order (Horner form with the factorials' reciprocals):
/// error below `0.25^8 / 8! = 4e-10`, under f32's resolution.
#[inline(always)]
fn exp_series(d: f32) -> f32 {
    const C: [f32; 8] = [
        1.0,
        1.0,
        1.0 / 2.0,
        1.0 / 6.0,
        1.0 / 24.0,
        1.0 / 120.0,
        1.0 / 720.0,
        1.0 / 5040.0,
    ];
    C[0] + d * (C[1] + d * (C[2] + d * (C[3] + d * (C[4] + d * (C[5] + d * (C[6] + d * C[7]))))))
}

/// `exp(d)` for `|d| <= 0.1` to 5th order: error below `0.1^6 / 6! = 1.4e-9`.
#[inline(always)]
fn exp_series5(d: f32) -> f32 {
    const C: [f32; 6] = [1.0, 1.0, 1.0 / 2.0, 1.0 / 6.0, 1.0 / 24.0, 1.0 / 120.0];
    C[0] + d * (C[1] + d * (C[2] + d * (C[3] + d * (C[4] + d * C[5]))))
}

/// The sum of frozen sources at many points (the same values as [`GaussianField::values_at`] for the
/// field's sources frozen by [`GaussianField::freeze_into`]): sensing freezes them once per step
/// instead of once per sensor.
pub fn frozen_values_at(sources: &[FrozenSource], points: &[Vec2], out: &mut [f32]) {
    out.fill(0.0);
    let (mut xs, mut ys) = ([0f32; MAX_GROUP], [0f32; MAX_GROUP]);
    for (points, out) in points.chunks(MAX_GROUP).zip(out.chunks_mut(MAX_GROUP)) {
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

    /// The analytic gradient matches central differences of eq. (5) (skewed, correlated source, points
    /// around it), and the value is `value_at`'s.
    #[test]
    fn gradient_matches_central_differences() {
        let source = GaussianSource {
            k: 1.3,
            sigma_x: 0.3,
            sigma_y: 0.15,
            rho: -0.4,
            evaporation: 6.0,
            centre: Vec2::new(0.6, 0.4),
            start: 0.0,
        };
        let frozen = source.at_time(1.5).unwrap();
        let h = 1e-3;
        for i in 0..12 {
            for j in 0..8 {
                let p = Vec2::new(0.05 + i as f32 * 0.1, 0.03 + j as f32 * 0.1);
                let (value, grad) = frozen.value_and_gradient(p);
                assert_eq!(value, frozen.value_at(p));
                let diff = |e: Vec2| {
                    let (a, b) = (p + e * h, p - e * h);
                    (frozen.value_at(a) as f64 - frozen.value_at(b) as f64)
                        / (a - b).length() as f64
                };
                let want = [diff(Vec2::X), diff(Vec2::Y)];
                for (g, w) in [grad.x, grad.y].into_iter().zip(want) {
                    assert!(
                        (g as f64 - w).abs() <= 2e-3 * w.abs() + 1e-3,
                        "at {p}: gradient {grad} vs differences {want:?}"
                    );
                }
            }
        }
    }

    /// A robot's four footprints sharing one `exp` (36 points up to 1.6 cm from their centroid) read
    /// the values of point-by-point evaluation to within 1e-6 relative (a few f32 ulps), for wide and
    /// narrow (per-point `exp`), round and skewed sources, near and far from the centre; a single
    /// point reads exactly `value_at`.
    #[test]
    fn shared_exp_footprints_match_pointwise_values() {
        let mut compared = 0;
        let mut worst = 0.0f64;
        for (sigma, rho) in [
            ((0.4, 0.4), 0.0),
            ((0.05, 0.12), 0.6),
            ((0.6, 0.2), -0.45),
            ((0.004, 0.006), 0.2),
        ] {
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
                    let points: Vec<Vec2> = (0..4)
                        .flat_map(|s| {
                            let sensor = c + 0.015 * Vec2::from_angle(s as f32 * 1.57 + 0.785);
                            (0..9).map(move |k| sensor + 0.00105 * Vec2::from_angle(k as f32 * 0.8))
                        })
                        .collect();
                    let mut got = vec![0.0; points.len()];
                    field.values_at(&points, &mut got);
                    for (p, &g) in points.iter().zip(&got) {
                        let want = field.value_at(*p);
                        let err = (g - want).abs() as f64 / (want as f64).max(1e-30);
                        worst = worst.max(err);
                        assert!(
                            err <= 1e-6 || (g - want).abs() < 1e-35,
                            "sigma {sigma:?} rho {rho} at {p}: {g} vs {want}"
                        );
                        compared += usize::from(g > 1e-3);
                    }
                    let mut one = [0.0];
                    field.values_at(&points[..1], &mut one);
                    assert_eq!(one[0], field.value_at(points[0]));
                }
            }
        }
        eprintln!("worst relative difference {worst:e}");
        assert!(
            compared > 20_000,
            "only {compared} non-negligible values compared"
        );
    }
}
