//! Grid model, eq. (2): dPhi/dt = -Phi/e + d lap(Phi) - u.grad(Phi) + J.
//!
//! One [`GridField::step`] executes a [`StepPlan`] in three parts, in this order:
//!
//! 1. evaporation and static injection, integrated exactly per cell:
//!    `Phi <- a Phi + b J` with `a = exp(-dt/e)` and `b = e (1 - a)` (`b = dt` when `e` is infinite);
//! 2. diffusion, by the [`DiffusionScheme`] of the field (conservative, no-flux walls, never negative);
//! 3. wind advection, first-order upwind in conservative flux form with no-flux walls, sub-stepped to a
//!    Courant number of at most 1/2 per direction (so it never goes negative and conserves mass).
//!
//! With the default [`DiffusionScheme::Auto`] and `d dt / h^2 <= 1/4`, parts 1 and 2 are one fused pass
//! that reads every cell once and writes it once, in place.
//!
//! Large grids are processed in parallel with rayon (bands of rows, or strips of columns for the
//! vertical sweeps); small grids run on the calling thread. Every output cell is computed by the same
//! arithmetic whatever the partition, so results are bit-identical for any number of threads.
#![allow(clippy::neg_cmp_op_on_partial_ord, clippy::needless_range_loop)] // NaN-aware tests; index loops over several equal-length slices

mod advection;
mod deposit;
mod explicit;
mod implicit;
mod one_sided;
mod sampling;
mod spec;
mod strips;

pub use deposit::GridBand;
#[cfg(test)]
pub(crate) use deposit::test_segments;
pub use implicit::thomas_coefficients;
pub(crate) use sampling::lerp_index;
pub use sampling::{Bilinear, bilinear_mix};
pub use spec::{DiffusionScheme, GridParams, GridSpec};

use super::CellBuffer;
use super::step_plan::{Diffusion, StepPlan};
use implicit::Thomas;
use rayon::prelude::*;

/// Grids with fewer cells than this run on the calling thread (rayon's overhead is not worth it).
pub const PARALLEL_MIN_CELLS: usize = 1 << 17;
/// Rows per parallel task of the row-wise passes.
const BAND_ROWS: usize = 16;

/// One pheromone on a grid.
pub struct GridField {
    spec: GridSpec,
    params: GridParams,
    values: CellBuffer,
    injection: Option<Vec<f32>>,
    /// Second buffer of the one-sided passes (swapped with `values`).
    scratch: CellBuffer,
    /// Row buffers of the explicit passes.
    explicit_rows: explicit::ExplicitRows,
    thomas_x: Option<Box<Thomas>>,
    thomas_y: Option<Box<Thomas>>,
    /// Log of (exact cumulative decay / applied cumulative decay): error feedback that keeps the product
    /// of the f32 decay factors within one rounding of `exp(-t/e)` over any number of steps.
    decay_carry: f64,
}

impl GridField {
    pub fn new(spec: GridSpec, params: GridParams) -> Self {
        GridField {
            spec,
            params,
            values: CellBuffer::zeros(spec.len()),
            injection: None,
            scratch: CellBuffer::default(),
            explicit_rows: Default::default(),
            thomas_x: None,
            thomas_y: None,
            decay_carry: 0.0,
        }
    }
    pub fn spec(&self) -> &GridSpec {
        &self.spec
    }
    pub fn params(&self) -> &GridParams {
        &self.params
    }
    /// The running decay correction of the field's steps (see [`StepPlan::new`](super::StepPlan::new)):
    /// a copy of the field stepped elsewhere (a GPU batch) starts from it to take the same decay factors.
    pub fn decay_carry(&self) -> f64 {
        self.decay_carry
    }
    /// Replaces the parameters (the cached implicit coefficients are rebuilt when needed).
    pub fn set_params(&mut self, params: GridParams) {
        self.params = params;
    }
    pub fn values(&self) -> &[f32] {
        &self.values
    }
    pub fn values_mut(&mut self) -> &mut [f32] {
        &mut self.values
    }
    /// Sets every cell to zero.
    pub fn clear(&mut self) {
        self.values.fill(0.0);
    }
    /// Sets a static injection map `J` (units per second per cell), applied every step.
    pub fn set_static_injection(&mut self, j: Vec<f32>) {
        assert_eq!(j.len(), self.spec.len());
        self.injection = Some(j);
    }
    /// The static injection map, if any.
    pub fn static_injection(&self) -> Option<&[f32]> {
        self.injection.as_deref()
    }
    /// Removes the static injection map.
    pub fn clear_static_injection(&mut self) {
        self.injection = None;
    }
    /// Keeps the values as they are for ever: no static injection, no evaporation (a field at its
    /// steady state without diffusion or wind stays there exactly, and stepping it costs nothing new).
    pub fn freeze(&mut self) {
        self.injection = None;
        self.params.evaporation = f32::INFINITY;
    }
    /// Sets every cell to `e J`, the level a static injection `J` under evaporation `e` settles at
    /// without diffusion or wind, where the field has a static injection and a finite positive
    /// evaporation; returns whether it did.
    pub fn fill_steady_state(&mut self) -> bool {
        let e = self.params.evaporation;
        let Some(j) = self.injection.as_deref() else {
            return false;
        };
        if !(e.is_finite() && e > 0.0) {
            return false;
        }
        for (v, j) in self.values.iter_mut().zip(j) {
            *v = e * j;
        }
        true
    }

    /// Integral of the field, sum of values times cell area.
    pub fn total_mass(&self) -> f64 {
        let h = self.spec.cell as f64;
        self.values.iter().map(|&v| v as f64).sum::<f64>() * h * h
    }

    /// Advances by `dt` seconds: exact evaporation and static injection, then diffusion and wind.
    pub fn step(&mut self, dt: f32) {
        if let Some(plan) = StepPlan::new(&self.spec, &self.params, dt, &mut self.decay_carry) {
            self.execute(&plan);
        }
    }

    /// Runs the passes of `plan` (made for this field's spec and parameters).
    fn execute(&mut self, plan: &StepPlan) {
        let GridSpec { nx, ny, .. } = self.spec;
        let (a, b) = (plan.a, plan.b);
        let parallel = self.spec.len() >= PARALLEL_MIN_CELLS;
        match plan.diffusion {
            Diffusion::None => self.evaporate_inject(a, b, parallel),
            Diffusion::Explicit { substeps, r } => self.explicit(a, b, r, substeps, parallel),
            Diffusion::Implicit { r } => self.implicit(a, b, r, parallel),
            Diffusion::Uniform => {
                self.evaporate_inject(a, b, parallel);
                let mean = (self.values.iter().map(|&v| v as f64).sum::<f64>()
                    / self.values.len() as f64) as f32;
                self.values.fill(mean);
            }
            Diffusion::OneSided { substeps, s } => {
                self.evaporate_inject(a, b, parallel);
                for _ in 0..substeps {
                    self.one_sided_pass(s, parallel);
                }
            }
        }
        if let Some(wind) = plan.wind {
            let (cx, cy) = (wind.x(&self.spec), wind.y(&self.spec));
            for _ in 0..wind.substeps {
                if let Some(c) = cx {
                    advection::advect_x(&mut self.values, nx, c, parallel);
                }
                if let Some(c) = cy {
                    advection::advect_y(&mut self.values, nx, ny, c, parallel);
                }
            }
        }
    }

    /// `Phi <- a Phi + b J`, in place.
    fn evaporate_inject(&mut self, a: f32, b: f32, parallel: bool) {
        let chunk = self.spec.nx.max(1) * BAND_ROWS;
        match &self.injection {
            Some(j) => {
                let f = |(v, j): (&mut [f32], &[f32])| {
                    for (v, &j) in v.iter_mut().zip(j) {
                        *v = flush(a * *v + b * j);
                    }
                };
                if parallel {
                    self.values
                        .par_chunks_mut(chunk)
                        .zip(j.par_chunks(chunk))
                        .for_each(f);
                } else {
                    self.values
                        .chunks_mut(chunk)
                        .zip(j.chunks(chunk))
                        .for_each(f);
                }
            }
            None => {
                if a == 1.0 {
                    return;
                }
                let f = |v: &mut [f32]| v.iter_mut().for_each(|v| *v = flush(*v * a));
                if parallel {
                    self.values.par_chunks_mut(chunk).for_each(f);
                } else {
                    self.values.chunks_mut(chunk).for_each(f);
                }
            }
        }
    }
}

/// Values at or below this are set to zero (and so are NaN and negative values): it keeps every pass
/// free of subnormal floats, whose arithmetic is up to a hundred times slower on common CPUs, at a
/// cost of at most 1e-30 units per cell per pass.
pub const FLUSH_BELOW: f32 = 1e-30;

#[inline(always)]
fn flush(v: f32) -> f32 {
    if v > FLUSH_BELOW { v } else { 0.0 }
}
