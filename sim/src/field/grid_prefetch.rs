//! Prefetching the grid cells that a robot's sensors will read. Sensing visits robots in index order,
//! and their cells are scattered over fields far larger than the caches: asking for the next robot's
//! cells while this one is being sensed overlaps their cache misses with useful work. Only a hint: it
//! never changes a result.
use super::{FieldModel, GridSpec, Pheromone};
use glam::Vec2;

/// Below this many cells per field (1 MiB of f32) the fields stay in the caches and prefetching is
/// only overhead.
const PREFETCH_MIN_CELLS: usize = 1 << 18;

/// The large grid fields of a world, all on one grid, ready to prefetch at points.
pub struct GridPrefetcher<'a> {
    spec: GridSpec,
    fields: Vec<&'a [f32]>,
}

impl<'a> GridPrefetcher<'a> {
    /// `None` when there is nothing worth prefetching (no grid field, or only small ones). Fields on
    /// a grid other than the first field's are left out (scenarios put every field on one grid).
    pub fn new(pheromones: &'a [Pheromone]) -> Option<Self> {
        let mut grids = pheromones.iter().filter_map(|ph| match &ph.model {
            FieldModel::Grid(g) => Some(g),
            FieldModel::Gaussian(_) => None,
        });
        let first = grids.next()?;
        let spec = *first.spec();
        if spec.len() < PREFETCH_MIN_CELLS || first.values().len() < spec.len() {
            return None;
        }
        let fields = std::iter::once(first)
            .chain(grids.filter(|g| *g.spec() == spec))
            .map(|g| g.values())
            .collect();
        Some(GridPrefetcher { spec, fields })
    }

    /// Hints the processor to fetch, in every field, the cells that interpolations at and near each of
    /// `points` read (rows `j0` and `j0 + 1` at column `i0`; a cache line holds the columns next to it).
    /// The cell index is computed once per point for all fields.
    #[inline]
    pub fn prefetch(&self, points: &[Vec2]) {
        let GridSpec { nx, ny, cell } = self.spec;
        for p in points {
            // Saturating conversions: NaN and negatives give 0.
            let i = ((p.x / cell - 0.5) as usize).min(nx - 1);
            let j = ((p.y / cell - 0.5) as usize).min(ny - 2);
            let row = j * nx + i;
            for values in &self.fields {
                // `row + nx < nx * ny <= values.len()`, as `j <= ny - 2` (large grids have ny >= 2).
                crate::prefetch::prefetch(&values[row]);
                crate::prefetch::prefetch(&values[row + nx]);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::field::{GridField, GridParams};

    fn grid_pheromone(nx: usize, ny: usize) -> Pheromone {
        Pheromone {
            name: "g".into(),
            colour: [255.0, 0.0, 0.0],
            model: FieldModel::Grid(GridField::new(
                GridSpec::new(nx, ny, 0.01),
                GridParams::default(),
            )),
        }
    }

    #[test]
    fn only_large_fields_on_the_first_grid_are_prefetched() {
        assert!(GridPrefetcher::new(&[grid_pheromone(100, 100)]).is_none());
        let big = [
            grid_pheromone(1440, 810),
            grid_pheromone(1440, 810),
            grid_pheromone(720, 405),
        ];
        let p = GridPrefetcher::new(&big).expect("large fields");
        assert_eq!(p.fields.len(), 2);
        // Any point, inside the grid or not (even NaN), is a valid hint.
        p.prefetch(&[
            Vec2::new(0.0, 0.0),
            Vec2::new(14.4, 8.1),
            Vec2::new(-3.0, 99.0),
            Vec2::NAN,
        ]);
    }
}
