//! Every Gaussian source of a world frozen at one instant (eq. (5)'s time factors computed), built
//! once per step and shared by all sensors: freezing per sensor cost an `exp`, a `sqrt` and four
//! divisions per source and sensor.
use super::{FieldModel, FrozenSource, Pheromone};

/// The started Gaussian sources of each pheromone, frozen at its field's time (empty for grids).
#[derive(Clone, Debug, Default)]
pub struct FrozenSources {
    per_pheromone: Vec<Vec<FrozenSource>>,
}

impl FrozenSources {
    pub fn new(pheromones: &[Pheromone]) -> Self {
        let mut frozen = FrozenSources::default();
        frozen.refresh(pheromones);
        frozen
    }

    /// Freezes the sources again (after the fields stepped or sources moved), reusing the buffers.
    pub fn refresh(&mut self, pheromones: &[Pheromone]) {
        self.per_pheromone.resize_with(pheromones.len(), Vec::new);
        for (out, ph) in self.per_pheromone.iter_mut().zip(pheromones) {
            out.clear();
            if let FieldModel::Gaussian(g) = &ph.model {
                g.freeze_into(out);
            }
        }
    }

    /// No started source in any pheromone.
    pub fn is_empty(&self) -> bool {
        self.per_pheromone.iter().all(Vec::is_empty)
    }

    /// The frozen sources of pheromone `index` (empty for a grid pheromone).
    #[inline]
    pub fn of(&self, index: usize) -> &[FrozenSource] {
        self.per_pheromone.get(index).map_or(&[], Vec::as_slice)
    }
}
