//! Gaussian-source model, eq. (5).
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
    pub fn value_at(&self, _p: Vec2, _t: f32) -> f32 {
        todo!()
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
    pub fn step(&mut self, dt: f32) {
        self.time += dt;
    }
}
