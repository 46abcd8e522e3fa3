//! A uniform-grid spatial index of robot positions, shared by the disc physics (contacts) and the
//! bumpers (ray candidates).
use glam::Vec2;

/// Up to this many robots the index is a single cell: every robot is a candidate neighbour.
const SCAN_ALL_BELOW: usize = 32;

/// Uniform-grid hash of robot positions, rebuilt each step, so neighbour queries need no ray casts or
/// all-pairs scans.
///
/// Cell lists are built by a counting sort into flat arrays that are reused between rebuilds (no
/// allocation once the robot count and grid size settle). A query of reach `q` looks at the cells
/// within `q` of the point: cells of at least `q` keep it to 3 x 3 (smaller cells still work, they just
/// look at more cells).
#[derive(Default)]
pub struct NeighbourIndex {
    cell: f32,
    dims: [usize; 2],
    /// `starts[k]..starts[k + 1]` indexes `items` for cell `k`.
    starts: Vec<u32>,
    /// Robot indices sorted by cell.
    items: Vec<u32>,
    /// Cell of each robot.
    cell_of: Vec<u32>,
}

impl NeighbourIndex {
    pub fn rebuild(&mut self, arena: Vec2, cell: f32, positions: &[Vec2]) {
        // A handful of robots (a small world of a batched environment) is faster to scan than to
        // bucket: one cell over the whole arena. Bumper readings are a minimum over the candidates, so
        // they do not depend on the cell size.
        let whole_arena = arena.x.max(arena.y).max(1e-3);
        let cell = if positions.len() <= SCAN_ALL_BELOW {
            whole_arena
        } else if cell.is_finite() && cell > 0.0 {
            cell
        } else {
            whole_arena
        };
        // Bound the grid so a tiny cell cannot make a huge table.
        let max_cells_per_axis = 4096.0;
        let cell = cell
            .max(arena.x / max_cells_per_axis)
            .max(arena.y / max_cells_per_axis);
        self.cell = cell;
        if positions.len() <= SCAN_ALL_BELOW {
            // One cell (its bounds still clamp a query): the robots in index order, no sort. Already
            // so for as many robots (the usual step of a small world): nothing to rebuild.
            if self.dims == [1, 1] && self.items.len() == positions.len() {
                return;
            }
            self.dims = [1, 1];
            self.starts.clear();
            self.starts.extend([0, positions.len() as u32]);
            self.cell_of.clear();
            self.cell_of.resize(positions.len(), 0);
            self.items.clear();
            self.items.extend(0..positions.len() as u32);
            return;
        }
        let nx = ((arena.x / cell).ceil() as usize).max(1);
        let ny = ((arena.y / cell).ceil() as usize).max(1);
        self.dims = [nx, ny];
        let ncells = nx * ny;
        self.starts.clear();
        self.starts.resize(ncells + 1, 0);
        self.cell_of.clear();
        for &p in positions {
            let k = self.cell_index(p);
            self.cell_of.push(k as u32);
            self.starts[k + 1] += 1;
        }
        for k in 0..ncells {
            self.starts[k + 1] += self.starts[k];
        }
        self.items.clear();
        self.items.resize(positions.len(), 0);
        // Fill from the back of each cell so robots stay in index order within a cell.
        for (i, &k) in self.cell_of.iter().enumerate().rev() {
            let k = k as usize + 1;
            self.starts[k] -= 1;
            self.items[self.starts[k] as usize] = i as u32;
        }
        // After the fill, starts[k + 1] is the beginning of cell k: shift back by one.
        self.starts.rotate_left(1);
        self.starts[ncells] = positions.len() as u32;
    }

    /// Robots whose cell lies within `reach` of `p` (a superset of those within `reach`).
    pub fn near(&self, p: Vec2, reach: f32) -> impl Iterator<Item = usize> + '_ {
        let (x0, x1, y0, y1) = self.cell_range(p, reach);
        let nx = self.dims[0];
        (y0..y1).flat_map(move |y| {
            let a = self.starts[y * nx + x0] as usize;
            let b = self.starts[y * nx + x1] as usize;
            self.items[a..b].iter().map(|&i| i as usize)
        })
    }

    /// Calls `f` for every robot whose cell lies within `reach` of `p`, in a fixed order (the same
    /// robots as [`Self::near`], without the iterator overhead).
    #[inline]
    pub fn for_each_near(&self, p: Vec2, reach: f32, mut f: impl FnMut(usize)) {
        // One cell (a small world): every finite query covers it, and the cell range's clamped
        // conversions cost more than the handful of robots it holds.
        let (x0, x1, y0, y1) = if self.dims == [1, 1] {
            let n = usize::from(p.is_finite() && reach.is_finite());
            (0, n, 0, n)
        } else {
            self.cell_range(p, reach)
        };
        let nx = self.dims[0];
        for y in y0..y1 {
            let a = self.starts[y * nx + x0] as usize;
            let b = self.starts[y * nx + x1] as usize;
            for &i in &self.items[a..b] {
                f(i as usize);
            }
        }
    }

    /// Half-open cell ranges (x0..x1, y0..y1) covering the square of half-side `reach` around `p`.
    #[inline]
    fn cell_range(&self, p: Vec2, reach: f32) -> (usize, usize, usize, usize) {
        let [nx, ny] = self.dims;
        if nx == 0 || ny == 0 || !(p.is_finite() && reach.is_finite()) {
            return (0, 0, 0, 0);
        }
        let inv = 1.0 / self.cell;
        // `as usize` saturates negatives to 0 (and truncation is floor for non-negatives).
        let c = |v: f32, n: usize| ((v * inv) as usize).min(n - 1);
        (
            c(p.x - reach, nx),
            c(p.x + reach, nx) + 1,
            c(p.y - reach, ny),
            c(p.y + reach, ny) + 1,
        )
    }

    fn cell_index(&self, p: Vec2) -> usize {
        let [nx, ny] = self.dims;
        // `as usize` saturates negatives to 0 and truncates the rest: `floor(v / cell).max(0)`
        // without a libm `floorf` call (baseline x86-64 has no rounding instruction).
        let c = |v: f32, n: usize| {
            if v.is_finite() {
                ((v / self.cell) as usize).min(n - 1)
            } else {
                0
            }
        };
        c(p.y, ny) * nx + c(p.x, nx)
    }
}
