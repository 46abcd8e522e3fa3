//! Grid model, eq. (2): dPhi/dt = -Phi/e + d lap(Phi) - u.grad(Phi) + J.
use glam::Vec2;
use serde::{Deserialize, Serialize};

/// Geometry of a field grid: `nx * ny` square cells of side `cell` metres, cell `(i, j)` centred at
/// `((i + 0.5) cell, (j + 0.5) cell)`, stored row-major (`j * nx + i`, row `j = 0` at `y = 0`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GridSpec {
    pub nx: usize,
    pub ny: usize,
    /// Cell side, m.
    pub cell: f32,
}

impl GridSpec {
    /// The coarsest grid with cells no larger than `cell` that covers `size` (m).
    pub fn covering(size: Vec2, cell: f32) -> Self {
        let nx = ((size.x / cell).round() as usize).max(1);
        let ny = ((size.y / cell).round() as usize).max(1);
        GridSpec { nx, ny, cell: size.x / nx as f32 }
    }
    pub fn len(&self) -> usize {
        self.nx * self.ny
    }
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// How diffusion is integrated.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DiffusionScheme {
    /// Explicit symmetric 5-point Laplacian when `d dt / h^2 <= 1/4` (one fused pass), otherwise implicit.
    #[default]
    Auto,
    /// Explicit symmetric Laplacian, sub-stepped so that each sub-step is stable.
    Explicit,
    /// Backward-Euler, split by direction (unconditionally stable, positive, conservative).
    Implicit,
    /// The paper's one-sided scheme, eq. (4) (exchange with the left and lower neighbour only).
    OneSided,
}

/// Parameters of one grid field.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GridParams {
    /// Evaporation time constant `e`, s (`f32::INFINITY`: none).
    pub evaporation: f32,
    /// Diffusion coefficient `d`, m^2/s.
    pub diffusion: f32,
    pub scheme: DiffusionScheme,
    /// Constant wind (advection velocity), m/s.
    pub wind: Vec2,
}

impl Default for GridParams {
    fn default() -> Self {
        GridParams { evaporation: 10.0, diffusion: 0.0, scheme: DiffusionScheme::Auto, wind: Vec2::ZERO }
    }
}

/// One pheromone on a grid.
pub struct GridField {
    spec: GridSpec,
    params: GridParams,
    values: Vec<f32>,
    injection: Option<Vec<f32>>,
}

impl GridField {
    pub fn new(spec: GridSpec, params: GridParams) -> Self {
        GridField { spec, params, values: vec![0.0; spec.len()], injection: None }
    }
    pub fn spec(&self) -> &GridSpec {
        &self.spec
    }
    pub fn params(&self) -> &GridParams {
        &self.params
    }
    pub fn values(&self) -> &[f32] {
        &self.values
    }
    pub fn values_mut(&mut self) -> &mut [f32] {
        &mut self.values
    }
    /// Sets a static injection map `J` (units per second per cell), applied every step.
    pub fn set_static_injection(&mut self, j: Vec<f32>) {
        assert_eq!(j.len(), self.spec.len());
        self.injection = Some(j);
    }
    /// Bilinear value at `p` (m); clamped at the walls.
    pub fn value_at(&self, _p: Vec2) -> f32 {
        todo!()
    }
    /// Adds `amount * kernel.weight(distance to segment a-b)` to every cell near the segment.
    pub fn deposit_segment(&mut self, _kernel: &crate::field::Kernel, _a: Vec2, _b: Vec2, _amount: f32) {
        todo!()
    }
    /// Advances by `dt` seconds: exact evaporation and static injection, then diffusion and wind.
    pub fn step(&mut self, _dt: f32) {
        todo!()
    }
    /// Integral of the field, sum of values times cell area.
    pub fn total_mass(&self) -> f64 {
        todo!()
    }
}
