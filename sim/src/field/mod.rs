//! Pheromone fields: the grid model of eq. (2), the Gaussian-source model of eq. (5), injection kernels
//! and static injection maps. A [`Pheromone`] is one named field with its drawing colour.

mod backend;
mod cells;
mod frozen;
mod gaussian;
mod grid;
mod grid_prefetch;
mod grid_sampler;
mod kernel;
mod nearby;
mod pheromone;
mod static_map;
mod step_plan;

pub use backend::{BackendChoice, FieldBackend};
pub use cells::CellBuffer;
pub use frozen::FrozenSources;
pub use gaussian::{FrozenSource, GaussianField, GaussianSource, MAX_GROUP};
pub(crate) use grid::lerp_index;
#[cfg(test)]
pub(crate) use grid::test_segments;
pub use grid::{
    Bilinear, DiffusionScheme, GridBand, GridField, GridParams, GridSpec, PARALLEL_MIN_CELLS,
    bilinear_mix, thomas_coefficients,
};
pub use grid_prefetch::GridPrefetcher;
pub(crate) use grid_sampler::GridSampler;
pub use kernel::Kernel;
pub use nearby::NearbyPoints;
#[cfg(test)]
pub(crate) use pheromone::grid_and_gaussian;
pub use pheromone::{FieldModel, Pheromone};
pub use static_map::{image_map, polyline_map};
pub use step_plan::{Diffusion, EXPLICIT_MAX_R, ONE_SIDED_MAX_S, StepPlan, WIND_MAX_CFL, Wind};
