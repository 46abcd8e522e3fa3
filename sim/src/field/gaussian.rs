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
        Some(FrozenSource {
            amplitude: norm * decay,
            centre: self.centre,
            sx,
            sy,
            rho,
            one_m_rho2,
        })
    }
}

/// A source at one instant: eq. (5) as a function of position only.
#[derive(Clone, Copy, Debug)]
pub struct FrozenSource {
    amplitude: f64,
    centre: Vec2,
    sx: f64,
    sy: f64,
    rho: f64,
    one_m_rho2: f64,
}

impl FrozenSource {
    #[inline]
    pub fn value_at(&self, p: Vec2) -> f32 {
        let (sx, sy, rho) = (self.sx, self.sy, self.rho);
        let dx = (p.x - self.centre.x) as f64;
        let dy = (p.y - self.centre.y) as f64;
        let q = dx * dx / (sx * sx) + dy * dy / (sy * sy) - 2.0 * rho * dx * dy / (sx * sy);
        (self.amplitude * (-q / (2.0 * self.one_m_rho2)).exp()) as f32
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
    /// The field at many points: `out[k]` = the value at `points[k]` (same sum, in the same order, as
    /// [`GaussianField::value_at`], with each source's time factors computed once).
    pub fn values_at(&self, points: &[Vec2], out: &mut [f32]) {
        out.fill(0.0);
        for s in self.sources.iter().filter_map(|s| s.at_time(self.time)) {
            for (o, &p) in out.iter_mut().zip(points) {
                *o += s.value_at(p);
            }
        }
    }
    pub fn step(&mut self, dt: f32) {
        self.time += dt;
    }
}
