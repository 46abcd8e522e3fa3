//! The field set: every pheromone (grid fields with their static maps, Gaussian fields with their
//! sources), the backend that steps them, and the sources frozen for the current observations.
use crate::field::{FieldBackend, FieldModel, FrozenSources, Pheromone};
use glam::Vec2;
use rayon::prelude::*;

pub struct FieldSet {
    pheromones: Vec<Pheromone>,
    /// Steps the pheromones instead of the CPU when set (e.g. the GPU backend of `colcos-gpu`).
    backend: Option<Box<dyn FieldBackend>>,
    /// The Gaussian sources frozen at the time of the current observations.
    frozen: FrozenSources,
    /// The grid pheromones live outside the world (a GPU batch of many worlds' fields): the world
    /// neither steps them nor deposits into them nor senses them (see [`FieldSet::set_external_grids`]).
    external_grids: bool,
}

impl FieldSet {
    pub fn new(pheromones: Vec<Pheromone>) -> Self {
        FieldSet {
            pheromones,
            backend: None,
            frozen: FrozenSources::default(),
            external_grids: false,
        }
    }
    pub fn pheromones(&self) -> &[Pheromone] {
        &self.pheromones
    }
    pub fn pheromones_mut(&mut self) -> &mut [Pheromone] {
        &mut self.pheromones
    }
    /// Installs a backend that steps the pheromones from now on (`None`: the CPU).
    pub fn set_backend(&mut self, backend: Option<Box<dyn FieldBackend>>) {
        self.backend = backend;
    }
    /// Hands the grid pheromones to an owner outside the world (`true`), e.g. a GPU batch that steps
    /// many worlds' fields, deposits their trails and senses their colours at once. From then on a
    /// step leaves the grids' CPU values as they are (they go stale), keeps its trail segments in
    /// [`crate::world::Injection::segments`], and ends without colour sensing: the owner hands the
    /// footprints' level sums to [`crate::world::World::sense_from_sums`].
    pub fn set_external_grids(&mut self, external: bool) {
        self.external_grids = external;
    }
    /// Whether the grid pheromones are stepped outside the world.
    pub fn external_grids(&self) -> bool {
        self.external_grids
    }
    /// The installed backend's description, or `None` for the CPU.
    pub fn backend_description(&self) -> Option<String> {
        self.backend.as_ref().map(|b| b.describe())
    }
    /// The Gaussian sources as frozen for the current observations.
    pub fn frozen(&self) -> &FrozenSources {
        &self.frozen
    }
    /// Freezes the Gaussian sources at the fields' current time (sensing reads them frozen).
    pub fn freeze(&mut self) {
        self.frozen.refresh(&self.pheromones);
    }

    /// Pheromone `index`'s value at `p` as of the current observations: the same value as
    /// [`Pheromone::value_at`] then, with Gaussian sources as frozen once for this step's sensing (a
    /// task's reward reads the field at many points without recomputing each source's time factors).
    pub fn value_observed(&self, index: usize, p: Vec2) -> f32 {
        match &self.pheromones[index].model {
            FieldModel::Grid(g) => g.value_at(p),
            // Sources that have not started are left out of the frozen set; they add 0.0.
            FieldModel::Gaussian(_) => self
                .frozen
                .of(index)
                .iter()
                .fold(0.0, |sum, s| sum + s.value_at(p)),
        }
    }

    /// [`FieldSet::value_observed`] and its gradient at `p` (per m): analytic for Gaussian sources
    /// (one `exp` per source), central differences `step` m apart on a grid.
    pub fn value_and_gradient_observed(&self, index: usize, p: Vec2, step: f32) -> (f32, Vec2) {
        match &self.pheromones[index].model {
            FieldModel::Grid(g) => {
                let (hx, hy) = (Vec2::X * step, Vec2::Y * step);
                let inv = 1.0 / (2.0 * step);
                let grad = Vec2::new(
                    g.value_at(p + hx) - g.value_at(p - hx),
                    g.value_at(p + hy) - g.value_at(p - hy),
                ) * inv;
                (g.value_at(p), grad)
            }
            FieldModel::Gaussian(_) => {
                self.frozen
                    .of(index)
                    .iter()
                    .fold((0.0, Vec2::ZERO), |(value, grad), s| {
                        let (v, g) = s.value_and_gradient(p);
                        (value + v, grad + g)
                    })
            }
        }
    }
}

/// Stage `step_fields`: advances every pheromone by `dt` (evaporation, diffusion, wind, static
/// injection; the Gaussian fields' clocks), on the installed backend when there is one, else each
/// field's own pass, side by side when `parallel` (a large field's pass also splits into bands).
///
/// Reads and writes the pheromones only.
pub fn step_fields(fields: &mut FieldSet, dt: f32, parallel: bool) {
    let pheromones = &mut fields.pheromones;
    if fields.external_grids {
        // The grids are stepped by their owner; the Gaussian fields' clocks still advance here.
        pheromones
            .iter_mut()
            .filter(|p| !matches!(p.model, FieldModel::Grid(_)))
            .for_each(|p| p.step(dt));
        return;
    }
    match fields.backend.as_mut() {
        Some(backend) => backend.step(pheromones, dt),
        None if parallel => pheromones.par_iter_mut().for_each(|p| p.step(dt)),
        None => pheromones.iter_mut().for_each(|p| p.step(dt)),
    }
}
