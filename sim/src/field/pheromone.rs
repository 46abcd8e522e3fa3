//! One named pheromone: a field model and the colour it is drawn in.
use super::{GaussianField, GridField};
use glam::Vec2;

pub enum FieldModel {
    Grid(GridField),
    Gaussian(GaussianField),
}

pub struct Pheromone {
    pub name: String,
    /// k_j of eq. (1): 8-bit screen levels per unit of pheromone, for (r, g, b).
    pub colour: [f32; 3],
    pub model: FieldModel,
}

impl Pheromone {
    pub fn value_at(&self, p: Vec2) -> f32 {
        match &self.model {
            FieldModel::Grid(g) => g.value_at(p),
            FieldModel::Gaussian(g) => g.value_at(p),
        }
    }
    pub fn step(&mut self, dt: f32) {
        match &mut self.model {
            FieldModel::Grid(g) => g.step(dt),
            FieldModel::Gaussian(g) => g.step(dt),
        }
    }
}

/// A grid pheromone ("grid") and a Gaussian one ("gauss") drawn in `colours`: the pair of fields
/// the screen's and the sensors' fast paths are checked on.
#[cfg(test)]
pub(crate) fn grid_and_gaussian(
    grid: GridField,
    gaussian: GaussianField,
    colours: [[f32; 3]; 2],
) -> [Pheromone; 2] {
    [
        Pheromone {
            name: "grid".into(),
            colour: colours[0],
            model: FieldModel::Grid(grid),
        },
        Pheromone {
            name: "gauss".into(),
            colour: colours[1],
            model: FieldModel::Gaussian(gaussian),
        },
    ]
}
