//! Grid model, eq. (2): dPhi/dt = -Phi/e + d lap(Phi) - u.grad(Phi) + J.
//!
//! One [`GridField::step`] is split into three parts, in this order:
//!
//! 1. evaporation and static injection, integrated exactly per cell:
//!    `Phi <- a Phi + b J` with `a = exp(-dt/e)` and `b = e (1 - a)` (`b = dt` when `e` is infinite);
//! 2. diffusion, by the [`DiffusionScheme`] of the field (conservative, no-flux walls, never negative);
//! 3. wind advection, first-order upwind in conservative flux form with no-flux walls, sub-stepped to a
//!    Courant number of at most 1/2 per direction (so it never goes negative and conserves mass).
//!
//! With the default [`DiffusionScheme::Auto`] and `d dt / h^2 <= 1/4`, parts 1 and 2 are one fused pass
//! that reads every cell once and writes it once (into a second buffer, then swapped).
//!
//! Large grids are processed in parallel with rayon (bands of rows, or strips of columns for the
//! vertical sweeps); small grids run on the calling thread. Every output cell is computed by the same
//! arithmetic whatever the partition, so results are bit-identical for any number of threads.
#![allow(clippy::neg_cmp_op_on_partial_ord, clippy::needless_range_loop)] // NaN-aware tests; index loops over several equal-length slices
use super::CellBuffer;
use glam::Vec2;
use rayon::prelude::*;
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
        GridSpec {
            nx,
            ny,
            cell: size.x / nx as f32,
        }
    }
    pub fn len(&self) -> usize {
        self.nx * self.ny
    }
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
    /// Extent of the grid, m: `(nx cell, ny cell)`.
    pub fn size(&self) -> Vec2 {
        Vec2::new(self.nx as f32 * self.cell, self.ny as f32 * self.cell)
    }
    /// Centre of cell `(i, j)`, m.
    pub fn cell_centre(&self, i: usize, j: usize) -> Vec2 {
        Vec2::new((i as f32 + 0.5) * self.cell, (j as f32 + 0.5) * self.cell)
    }
    /// Index range `[lo, hi)` of the cells whose centres may lie within `[lo_m, hi_m]` along one axis of
    /// `n` cells.
    pub(crate) fn cell_range(&self, lo_m: f32, hi_m: f32, n: usize) -> (usize, usize) {
        let lo = ((lo_m / self.cell - 0.5).floor().max(0.0) as usize).min(n);
        let hi = (((hi_m / self.cell - 0.5).ceil() + 1.0).max(0.0) as usize).min(n);
        (lo, hi.max(lo))
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
    ///
    /// Read conservatively, eq. (4) makes every cell send `s/2` of its content to its right neighbour and
    /// `s/2` to its upper neighbour per unit of `s = d dt / h^2` (what a cell receives from its left and
    /// lower neighbours leaves them). Mass is conserved, but it is transported: the scheme is a
    /// first-order upwind advection toward `+x` and `+y` at `d / (2h)` m/s, so mass drifts toward
    /// `+x`/`+y` and piles up against those walls. Offered for fidelity to the paper only. Sub-stepped to
    /// `s <= 1/2` per sub-step.
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
        GridParams {
            evaporation: 10.0,
            diffusion: 0.0,
            scheme: DiffusionScheme::Auto,
            wind: Vec2::ZERO,
        }
    }
}

/// Grids with fewer cells than this run on the calling thread (rayon's overhead is not worth it).
pub const PARALLEL_MIN_CELLS: usize = 1 << 17;
/// Rows per parallel task of the row-wise passes.
const BAND_ROWS: usize = 16;
/// Columns per strip of the column-wise sweeps (implicit y-solve, vertical wind).
const STRIP_COLS: usize = 128;
/// Rows solved together (interleaved) by the implicit x-solve.
const XSOLVE_ROWS: usize = 8;
/// Largest explicit diffusion number `d dt / h^2` per (sub-)step.
const EXPLICIT_MAX_R: f32 = 0.25;
/// Largest one-sided number `d dt / h^2` per sub-step.
const ONE_SIDED_MAX_S: f32 = 0.5;
/// Largest Courant number per wind sub-step, per direction.
const WIND_MAX_CFL: f32 = 0.5;

/// Precomputed Thomas-algorithm coefficients for the backward-Euler system of one direction:
/// `(1 + 2r) u_i - r u_{i-1} - r u_{i+1} = f_i` with no-flux ends (`(1 + r) u_0 - r u_1 = f_0`).
/// Forward: `d_i = (f_i + r d_{i-1}) m_i`; backward: `u_i = d_i + cp_i u_{i+1}`. All coefficients are
/// positive, so the solve maps non-negative data to non-negative data.
#[derive(Clone, Debug)]
struct Thomas {
    n: usize,
    r: f32,
    m: Vec<f32>,
    cp: Vec<f32>,
}

/// Thomas-algorithm coefficients (m, cp) for `(1 + 2r) u_i - r u_{i-1} - r u_{i+1} = f_i` with no-flux
/// ends, computed in f64 and rounded to f32 (shared with the GPU backend so both solve identically).
pub fn thomas_coefficients(n: usize, r: f32) -> (Vec<f32>, Vec<f32>) {
    let rr = r as f64;
    let mut m = vec![0f32; n];
    let mut cp = vec![0f32; n];
    let mut prev_cp = 0f64;
    for i in 0..n {
        let diag = if n == 1 {
            1.0
        } else if i == 0 || i == n - 1 {
            1.0 + rr
        } else {
            1.0 + 2.0 * rr
        };
        let mi = 1.0 / (diag - rr * prev_cp);
        let cpi = if i + 1 < n { rr * mi } else { 0.0 };
        m[i] = mi as f32;
        cp[i] = cpi as f32;
        prev_cp = cpi;
    }
    (m, cp)
}

impl Thomas {
    fn new(n: usize, r: f32) -> Self {
        let (m, cp) = thomas_coefficients(n, r);
        Thomas { n, r, m, cp }
    }

    fn matches(&self, n: usize, r: f32) -> bool {
        self.n == n && self.r.to_bits() == r.to_bits()
    }
}

/// One pheromone on a grid.
pub struct GridField {
    spec: GridSpec,
    params: GridParams,
    values: CellBuffer,
    injection: Option<Vec<f32>>,
    /// Second buffer of the explicit passes (swapped with `values`).
    scratch: CellBuffer,
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

    /// Bilinear value at `p` (m); clamped at the walls.
    pub fn value_at(&self, p: Vec2) -> f32 {
        match Bilinear::at(&self.spec, p) {
            Some(b) => self.bilinear(&b),
            None => 0.0,
        }
    }

    /// The value at a point whose interpolation weights were computed once for this grid's spec
    /// (several fields on the same grid share them; see [`Bilinear`]).
    #[inline]
    pub fn bilinear(&self, b: &Bilinear) -> f32 {
        let v = &self.values;
        let (r0, r1) = (b.j0 * self.spec.nx, b.j1 * self.spec.nx);
        bilinear_mix(
            v[r0 + b.i0],
            v[r0 + b.i1],
            v[r1 + b.i0],
            v[r1 + b.i1],
            b.tx,
            b.ty,
        )
    }

    /// Adds `amount * kernel.weight(distance to segment a-b)` to every cell near the segment.
    /// Only cells of the segment's bounding box grown by the kernel's support are visited, and of
    /// those only the ones each row can bring within the support. `a == b` is a point deposit. A
    /// kernel narrower than half a cell may touch no cell centre and deposit nothing.
    pub fn deposit_segment(
        &mut self,
        kernel: &crate::field::Kernel,
        a: Vec2,
        b: Vec2,
        amount: f32,
    ) {
        let ny = self.spec.ny;
        self.band_mut(0, ny).deposit_segment(kernel, a, b, amount);
    }

    /// Rows `first_row..first_row + rows` (clamped to the grid) as a band that takes deposits.
    pub fn band_mut(&mut self, first_row: usize, rows: usize) -> GridBand<'_> {
        let GridSpec { nx, ny, .. } = self.spec;
        let first_row = first_row.min(ny);
        let rows = rows.min(ny - first_row);
        GridBand {
            spec: self.spec,
            first_row,
            values: &mut self.values[first_row * nx..(first_row + rows) * nx],
        }
    }

    /// The grid cut into bands of `rows` rows (the last may be shorter): deposits into different
    /// bands can run in parallel, and a cell's deposits still arrive in the order they are made
    /// when every band takes every deposit in that order.
    pub fn bands_mut(&mut self, rows: usize) -> impl Iterator<Item = GridBand<'_>> {
        let spec = self.spec;
        let rows = rows.max(1);
        self.values
            .chunks_mut((rows * spec.nx).max(1))
            .enumerate()
            .map(move |(k, values)| GridBand {
                spec,
                first_row: k * rows,
                values,
            })
    }

    /// Adds `amount * kernel.weight(distance to p)` to every cell near `p`.
    pub fn deposit_point(&mut self, kernel: &crate::field::Kernel, p: Vec2, amount: f32) {
        self.deposit_segment(kernel, p, p, amount);
    }

    /// Advances by `dt` seconds: exact evaporation and static injection, then diffusion and wind.
    pub fn step(&mut self, dt: f32) {
        if !(dt > 0.0) || self.spec.is_empty() {
            return;
        }
        let GridSpec { nx, ny, cell } = self.spec;
        let e = self.params.evaporation as f64;
        let dtd = dt as f64;
        let (a, b) = if e.is_finite() && e > 0.0 {
            // The f32 factor actually applied is chosen so that the running product tracks exp(-t/e), and
            // b = e (1 - a) is the exact injection for that factor (so the steady state is e J).
            let ln_a = -dtd / e + self.decay_carry;
            let a = ln_a.exp() as f32;
            self.decay_carry = ln_a - (a as f64).ln();
            (a, (e * (1.0 - a as f64)) as f32)
        } else if e.is_finite() {
            // e <= 0: the pheromone vanishes at once; the injection of this step is not kept either.
            (0.0, 0.0)
        } else {
            (1.0, dt)
        };
        let d = self.params.diffusion.max(0.0);
        let r = if d.is_finite() {
            d * dt / (cell * cell)
        } else {
            f32::INFINITY
        };
        let parallel = self.spec.len() >= PARALLEL_MIN_CELLS;
        let has_diffusion = r > 0.0 && (nx > 1 || ny > 1);

        if !has_diffusion {
            self.evaporate_inject(a, b, parallel);
        } else {
            match self.params.scheme {
                DiffusionScheme::Auto if r <= EXPLICIT_MAX_R => self.explicit(a, b, r, 1, parallel),
                DiffusionScheme::Auto | DiffusionScheme::Implicit => {
                    if r.is_finite() {
                        self.implicit(a, b, r, parallel)
                    } else {
                        // Infinite diffusion: uniform at the mean.
                        self.evaporate_inject(a, b, parallel);
                        let mean = (self.values.iter().map(|&v| v as f64).sum::<f64>()
                            / self.values.len() as f64) as f32;
                        self.values.fill(mean);
                    }
                }
                DiffusionScheme::Explicit => {
                    let n = substeps(r, EXPLICIT_MAX_R);
                    self.explicit(a, b, r / n as f32, n, parallel)
                }
                DiffusionScheme::OneSided => {
                    self.evaporate_inject(a, b, parallel);
                    let n = substeps(r, ONE_SIDED_MAX_S);
                    let s = r / n as f32;
                    for _ in 0..n {
                        self.one_sided_pass(s, parallel);
                    }
                }
            }
        }

        let wind = self.params.wind;
        if wind != Vec2::ZERO && wind.is_finite() {
            let cx = wind.x * dt / cell;
            let cy = wind.y * dt / cell;
            let n = substeps(cx.abs().max(cy.abs()), WIND_MAX_CFL);
            let (cx, cy) = (cx / n as f32, cy / n as f32);
            for _ in 0..n {
                if cx != 0.0 && nx > 1 {
                    advect_x(&mut self.values, nx, cx, parallel);
                }
                if cy != 0.0 && ny > 1 {
                    advect_y(&mut self.values, nx, ny, cy, parallel);
                }
            }
        }
    }

    /// Integral of the field, sum of values times cell area.
    pub fn total_mass(&self) -> f64 {
        let h = self.spec.cell as f64;
        self.values.iter().map(|&v| v as f64).sum::<f64>() * h * h
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

    /// `n` explicit sub-steps of diffusion number `r`; the first is fused with evaporation and injection.
    fn explicit(&mut self, a: f32, b: f32, r: f32, n: usize, parallel: bool) {
        let GridSpec { nx, ny, .. } = self.spec;
        for k in 0..n {
            let inj = if k == 0 {
                self.injection.as_deref()
            } else {
                None
            };
            let (a, b) = if k == 0 { (a, b) } else { (1.0, 0.0) };
            explicit_pass(&mut self.values, inj, nx, ny, a, b, r, parallel);
        }
    }

    /// Backward Euler split by direction: x-solve (fused with evaporation and injection), then y-solve.
    fn implicit(&mut self, a: f32, b: f32, r: f32, parallel: bool) {
        let GridSpec { nx, ny, .. } = self.spec;
        if !self.thomas_x.as_ref().is_some_and(|t| t.matches(nx, r)) {
            self.thomas_x = Some(Box::new(Thomas::new(nx, r)));
        }
        if !self.thomas_y.as_ref().is_some_and(|t| t.matches(ny, r)) {
            self.thomas_y = Some(Box::new(Thomas::new(ny, r)));
        }
        let tx = self.thomas_x.as_ref().expect("set above");
        let ty = self.thomas_y.as_ref().expect("set above");
        let inj = self.injection.as_deref();
        let band = nx * XSOLVE_ROWS;
        let xsolve = |(k, rows): (usize, &mut [f32])| {
            let jrows = inj.map(|j| &j[k * band..k * band + rows.len()]);
            xsolve_rows(rows, jrows, nx, a, b, tx);
        };
        if parallel {
            self.values
                .par_chunks_mut(band)
                .enumerate()
                .for_each(xsolve);
        } else {
            self.values.chunks_mut(band).enumerate().for_each(xsolve);
        }
        if ny > 1 {
            let grid = StripGrid::new(&mut self.values, nx, ny);
            grid.for_each_strip(parallel, |s| ysolve_strip(s, ty));
        }
    }

    /// One sub-step of the conservative reading of eq. (4) with number `s = d dt / h^2`.
    fn one_sided_pass(&mut self, s: f32, parallel: bool) {
        let GridSpec { nx, ny, .. } = self.spec;
        if self.scratch.len() != self.values.len() {
            self.scratch = CellBuffer::zeros(self.values.len());
        }
        let src = &self.values;
        let half = 0.5 * s;
        let f = |(band, out): (usize, &mut [f32])| {
            for (k, orow) in out.chunks_mut(nx).enumerate() {
                let j = band * BAND_ROWS + k;
                let c = &src[j * nx..(j + 1) * nx];
                let dn = if j > 0 {
                    Some(&src[(j - 1) * nx..j * nx])
                } else {
                    None
                };
                // Outflow to the upper neighbour, if any.
                let keep_v = if j + 1 < ny { half } else { 0.0 };
                for i in 0..nx {
                    let keep_h = if i + 1 < nx { half } else { 0.0 };
                    let mut v = c[i] * (1.0 - keep_h - keep_v);
                    if i > 0 {
                        v += half * c[i - 1];
                    }
                    if let Some(dn) = dn {
                        v += half * dn[i];
                    }
                    orow[i] = flush(v);
                }
            }
        };
        if parallel {
            self.scratch
                .par_chunks_mut(nx * BAND_ROWS)
                .enumerate()
                .for_each(f);
        } else {
            self.scratch
                .chunks_mut(nx * BAND_ROWS)
                .enumerate()
                .for_each(f);
        }
        std::mem::swap(&mut self.values, &mut self.scratch);
    }
}

/// Number of sub-steps that bring `x` down to at most `max` each.
fn substeps(x: f32, max: f32) -> usize {
    if x <= max {
        1
    } else {
        ((x / max).ceil() as usize).max(1)
    }
}

/// Consecutive rows of a grid's values (see [`GridField::bands_mut`]): deposits land on the cells of
/// these rows only.
pub struct GridBand<'a> {
    spec: GridSpec,
    first_row: usize,
    values: &'a mut [f32],
}

impl GridBand<'_> {
    /// [`GridField::deposit_segment`] restricted to this band's rows: the same additions, in the
    /// same arithmetic, on the cells the band holds.
    pub fn deposit_segment(
        &mut self,
        kernel: &crate::field::Kernel,
        a: Vec2,
        b: Vec2,
        amount: f32,
    ) {
        let GridSpec { nx, ny, cell } = self.spec;
        let support = kernel.support();
        if !(support >= 0.0) || !a.is_finite() || !b.is_finite() {
            return;
        }
        // Deposits far from this band's rows (by more than a cell, so rounding cannot matter) are
        // skipped before any cell arithmetic: a band sees every deposit of its field.
        let band_end = self.first_row + self.values.len() / nx.max(1);
        let (band_lo, band_hi) = (self.first_row as f32 * cell, band_end as f32 * cell);
        if a.y.max(b.y) + support < band_lo - cell || a.y.min(b.y) - support > band_hi + cell {
            return;
        }
        let (j0, j1) = self
            .spec
            .cell_range(a.y.min(b.y) - support, a.y.max(b.y) + support, ny);
        let (j0, j1) = (j0.max(self.first_row), j1.min(band_end));
        if j0 >= j1 {
            return;
        }
        let (i0, i1) = self
            .spec
            .cell_range(a.x.min(b.x) - support, a.x.max(b.x) + support, nx);
        let ab = b - a;
        let len2 = ab.length_squared();
        // Most cells of the bounding box lie beyond the kernel (a disc covers a quarter of its
        // square). Per row, only cells whose centres come within `reach` of the segment's bounding
        // box are weighed: the distance to a segment is at least the distance to its bounding box,
        // and the margin over `support` dwarfs the rounding of both, so every cell the full box
        // would weigh non-zero is still weighed, with the same arithmetic.
        let reach = support * (1.0 + 1e-3) + cell * 1e-3;
        let (x_lo, x_hi) = (a.x.min(b.x), a.x.max(b.x));
        let (y_lo, y_hi) = (a.y.min(b.y), a.y.max(b.y));
        for j in j0..j1 {
            let y = (j as f32 + 0.5) * cell;
            let dy = (y_lo - y).max(y - y_hi).max(0.0);
            if dy > reach {
                continue;
            }
            let half = (reach * reach - dy * dy).max(0.0).sqrt();
            // Truncation is floor for the non-negative values here: the range may take one cell
            // more on each side, never one fewer.
            let first = ((((x_lo - half) / cell - 0.5).max(0.0)) as usize).max(i0);
            let end = ((((x_hi + half) / cell - 0.5).max(0.0)) as usize + 2).min(i1);
            let r = j - self.first_row;
            let row = &mut self.values[r * nx..(r + 1) * nx];
            for (i, v) in row.iter_mut().enumerate().take(end).skip(first) {
                let p = Vec2::new((i as f32 + 0.5) * cell, y);
                let dist = segment_distance(p, a, ab, len2);
                if dist <= support {
                    let w = kernel.weight(dist);
                    if w != 0.0 {
                        *v += amount * w;
                    }
                }
            }
        }
    }
}

/// Bilinear interpolation weights of one point on a grid: corner indices and fractions.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Bilinear {
    pub i0: usize,
    pub i1: usize,
    pub j0: usize,
    pub j1: usize,
    pub tx: f32,
    pub ty: f32,
}

/// Bilinear interpolation of corner values with [`GridField::value_at`]'s arithmetic (so that results
/// from values gathered elsewhere are bit-identical): `v00 = (i0, j0)`, `v10 = (i1, j0)`, ...
#[inline]
pub fn bilinear_mix(v00: f32, v10: f32, v01: f32, v11: f32, tx: f32, ty: f32) -> f32 {
    let lo = v00 + (v10 - v00) * tx;
    let hi = v01 + (v11 - v01) * tx;
    lo + (hi - lo) * ty
}

impl Bilinear {
    /// Weights of `p` on `spec` (points outside clamp to the edge cells); `None` for an empty grid.
    #[inline]
    pub fn at(spec: &GridSpec, p: Vec2) -> Option<Bilinear> {
        let GridSpec { nx, ny, cell } = *spec;
        if nx == 0 || ny == 0 {
            return None;
        }
        let (i0, i1, tx) = lerp_index(p.x / cell - 0.5, nx);
        let (j0, j1, ty) = lerp_index(p.y / cell - 0.5, ny);
        Some(Bilinear {
            i0,
            i1,
            j0,
            j1,
            tx,
            ty,
        })
    }
}

/// Index pair and weight for linear interpolation at fractional index `f` on `n` samples, clamped.
#[inline]
pub(crate) fn lerp_index(f: f32, n: usize) -> (usize, usize, f32) {
    if n <= 1 || !(f > 0.0) {
        return (0, 0, 0.0);
    }
    let max = (n - 1) as f32;
    if f >= max {
        return (n - 1, n - 1, 0.0);
    }
    // f > 0 here, so truncation is floor (and avoids a libm call on baseline x86-64).
    let i0 = (f as usize).min(n - 2);
    (i0, i0 + 1, f - i0 as f32)
}

/// Distance from `p` to the segment starting at `a` with direction `ab` (`len2 = |ab|^2`).
fn segment_distance(p: Vec2, a: Vec2, ab: Vec2, len2: f32) -> f32 {
    let t = if len2 > 0.0 {
        ((p - a).dot(ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p - (a + ab * t)).length()
}

/// Values at or below this are set to zero (and so are NaN and negative values): it keeps every pass
/// free of subnormal floats, whose arithmetic is up to a hundred times slower on common CPUs, at a
/// cost of at most 1e-30 units per cell per pass.
pub const FLUSH_BELOW: f32 = 1e-30;

#[inline(always)]
fn flush(v: f32) -> f32 {
    if v > FLUSH_BELOW { v } else { 0.0 }
}

/// `out = scale * (w c + r (left + right + up + down))` with `w = 1 - 4r`; a missing neighbour (wall)
/// counts as the cell itself, which is the no-flux condition. Every term is non-negative for
/// non-negative data and `r <= 1/4`.
#[inline(always)]
fn stencil_row(c: &[f32], up: &[f32], dn: &[f32], out: &mut [f32], scale: f32, r: f32) {
    let nx = c.len();
    let w = 1.0 - 4.0 * r;
    let (up, dn, out) = (&up[..nx], &dn[..nx], &mut out[..nx]);
    if nx == 1 {
        out[0] = flush(scale * (w * c[0] + r * ((c[0] + c[0]) + (up[0] + dn[0]))));
        return;
    }
    out[0] = flush(scale * (w * c[0] + r * ((c[0] + c[1]) + (up[0] + dn[0]))));
    let l = nx - 1;
    out[l] = flush(scale * (w * c[l] + r * ((c[l - 1] + c[l]) + (up[l] + dn[l]))));
    if nx > 2 {
        let n = nx - 2;
        let cl = &c[0..n];
        let cm = &c[1..n + 1];
        let cr = &c[2..n + 2];
        let u = &up[1..n + 1];
        let d = &dn[1..n + 1];
        let o = &mut out[1..n + 1];
        for k in 0..n {
            o[k] = flush(scale * (w * cm[k] + r * ((cl[k] + cr[k]) + (u[k] + d[k]))));
        }
    }
}

/// [`stencil_row`] (with `scale = 1`) whose upper row is `psi = a src_up + b J_up`, computed in the same
/// loop and stored into `up` for the next row (the same arithmetic as computing it first).
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn stencil_row_fused(
    c: &[f32],
    dn: &[f32],
    src_up: &[f32],
    inj_up: Option<&[f32]>,
    a: f32,
    b: f32,
    up: &mut [f32],
    out: &mut [f32],
    r: f32,
) {
    let nx = c.len();
    if nx < 3 {
        let psi = |i: usize| match inj_up {
            Some(q) => a * src_up[i] + b * q[i],
            None => a * src_up[i],
        };
        for i in 0..nx {
            up[i] = psi(i);
        }
        stencil_row(c, &up[..nx], dn, out, 1.0, r);
        return;
    }
    let w = 1.0 - 4.0 * r;
    let (dn, src_up, up, out) = (&dn[..nx], &src_up[..nx], &mut up[..nx], &mut out[..nx]);
    match inj_up {
        Some(q) => {
            let q = &q[..nx];
            for i in 0..nx {
                up[i] = a * src_up[i] + b * q[i];
            }
        }
        None => {
            // Edges here, interior fused below.
            up[0] = a * src_up[0];
            up[nx - 1] = a * src_up[nx - 1];
        }
    }
    let l = nx - 1;
    out[0] = flush(w * c[0] + r * ((c[0] + c[1]) + (up[0] + dn[0])));
    out[l] = flush(w * c[l] + r * ((c[l - 1] + c[l]) + (up[l] + dn[l])));
    let n = nx - 2;
    let cl = &c[0..n];
    let cm = &c[1..n + 1];
    let cr = &c[2..n + 2];
    let d = &dn[1..n + 1];
    let o = &mut out[1..n + 1];
    if inj_up.is_some() {
        let u = &up[1..n + 1];
        for k in 0..n {
            o[k] = flush(w * cm[k] + r * ((cl[k] + cr[k]) + (u[k] + d[k])));
        }
    } else {
        let su = &src_up[1..n + 1];
        let u = &mut up[1..n + 1];
        for k in 0..n {
            let uk = a * su[k];
            u[k] = uk;
            o[k] = flush(w * cm[k] + r * ((cl[k] + cr[k]) + (uk + d[k])));
        }
    }
}

/// One explicit pass in place, `values <- (1 + r lap) (a values + b J)`.
///
/// The rows are processed in bands (several per thread when parallel). Inside a band, rolling buffers
/// hold `psi = a Phi + b J` of the rows below, at and above the current one, computed from the old
/// values before the row is overwritten; the rows that neighbour a band from outside are computed into
/// halo buffers before the bands start. Every cell is therefore computed from the same old values by
/// the same arithmetic whatever the banding (bit-identical for any thread count), and memory is read
/// and written once, in place (no second buffer, so no extra read-for-ownership traffic).
#[allow(clippy::too_many_arguments)]
fn explicit_pass(
    values: &mut [f32],
    inj: Option<&[f32]>,
    nx: usize,
    ny: usize,
    a: f32,
    b: f32,
    r: f32,
    parallel: bool,
) {
    let nb = if parallel {
        (rayon::current_num_threads() * 4).min(ny / 8).max(1)
    } else {
        1
    };
    let starts: Vec<usize> = (0..=nb).map(|k| k * ny / nb).collect();
    let psi_into = |src: &[f32], j: usize, buf: &mut Vec<f32>| {
        buf.clear();
        let s = &src[j * nx..(j + 1) * nx];
        match inj {
            Some(jm) => {
                let q = &jm[j * nx..(j + 1) * nx];
                buf.extend(s.iter().zip(q).map(|(&v, &q)| a * v + b * q));
            }
            None => buf.extend(s.iter().map(|&v| a * v)),
        }
    };
    // Halo rows (psi of the old values) just outside each band: (below, above).
    let halos: Vec<Halo> = (0..nb)
        .map(|k| {
            let (j0, j1) = (starts[k], starts[k + 1]);
            let below = (j0 > 0).then(|| {
                let mut v = Vec::with_capacity(nx);
                psi_into(values, j0 - 1, &mut v);
                v
            });
            let above = (j1 < ny).then(|| {
                let mut v = Vec::with_capacity(nx);
                psi_into(values, j1, &mut v);
                v
            });
            (below, above)
        })
        .collect();
    let mut bands: Vec<(usize, &mut [f32])> = Vec::with_capacity(nb);
    let mut rest = values;
    for k in 0..nb {
        let (band, tail) = rest.split_at_mut((starts[k + 1] - starts[k]) * nx);
        bands.push((starts[k], band));
        rest = tail;
    }
    let run = |((j0, band), (below, above)): ((usize, &mut [f32]), &Halo)| {
        let args = BandArgs {
            j0,
            below: below.as_deref(),
            above: above.as_deref(),
            inj,
            nx,
            a,
            b,
            r,
        };
        explicit_band_dispatch(band, &args);
    };
    if parallel {
        bands.into_par_iter().zip(halos.par_iter()).for_each(run);
    } else {
        bands.into_iter().zip(halos.iter()).for_each(run);
    }
}

/// psi rows just below and just above a band (None at a wall).
type Halo = (Option<Vec<f32>>, Option<Vec<f32>>);

/// What one band of [`explicit_pass`] needs besides its rows.
struct BandArgs<'a> {
    /// First row of the band.
    j0: usize,
    /// psi of the row below the band (None at the wall).
    below: Option<&'a [f32]>,
    /// psi of the row above the band (None at the wall).
    above: Option<&'a [f32]>,
    inj: Option<&'a [f32]>,
    nx: usize,
    a: f32,
    b: f32,
    r: f32,
}

/// Runs [`explicit_band`] compiled for AVX2 where the CPU has it (twice the vector width of the
/// baseline SSE2). Both versions do the same IEEE operations per cell (no FMA contraction), so the
/// results are bit-identical.
fn explicit_band_dispatch(band: &mut [f32], args: &BandArgs<'_>) {
    #[cfg(target_arch = "x86_64")]
    {
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU supports AVX2 (checked just above).
            unsafe { explicit_band_avx2(band, args) };
            return;
        }
    }
    explicit_band(band, args);
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
/// # Safety
/// The CPU must support AVX2.
unsafe fn explicit_band_avx2(band: &mut [f32], args: &BandArgs<'_>) {
    explicit_band(band, args);
}

/// One band of rows of [`explicit_pass`], in place.
#[inline(always)]
fn explicit_band(band: &mut [f32], args: &BandArgs<'_>) {
    let BandArgs {
        j0,
        below,
        above,
        inj,
        nx,
        a,
        b,
        r,
    } = *args;
    let rows = band.len() / nx;
    if rows == 0 {
        return;
    }
    // psi over the band's own rows, local index, with the global injection row offset.
    let psi_local = |band: &[f32], jl: usize, buf: &mut Vec<f32>| {
        buf.clear();
        let s = &band[jl * nx..(jl + 1) * nx];
        match inj {
            Some(jm) => {
                let q = &jm[(j0 + jl) * nx..(j0 + jl + 1) * nx];
                buf.extend(s.iter().zip(q).map(|(&v, &q)| a * v + b * q));
            }
            None => buf.extend(s.iter().map(|&v| a * v)),
        }
    };
    let mut cur = Vec::with_capacity(nx);
    let mut next = Vec::with_capacity(nx);
    psi_local(band, 0, &mut cur);
    let mut prev = match below {
        Some(v) => v.to_vec(),
        None => cur.clone(),
    };
    for jl in 0..rows {
        if jl + 1 < rows {
            // psi of the row above is formed in the same loop as the stencil of this row.
            let (lo, hi) = band.split_at_mut((jl + 1) * nx);
            let q = inj.map(|jm| &jm[(j0 + jl + 1) * nx..(j0 + jl + 2) * nx]);
            next.resize(nx, 0.0);
            stencil_row_fused(
                &cur,
                &prev,
                &hi[..nx],
                q,
                a,
                b,
                &mut next,
                &mut lo[jl * nx..],
                r,
            );
        } else {
            next.clear();
            next.extend_from_slice(above.unwrap_or(&cur));
            stencil_row(
                &cur,
                &next,
                &prev,
                &mut band[jl * nx..(jl + 1) * nx],
                1.0,
                r,
            );
        }
        std::mem::swap(&mut prev, &mut cur);
        std::mem::swap(&mut cur, &mut next);
    }
}

/// Backward-Euler x-solve of up to `XSOLVE_ROWS` rows at once (their recurrences interleaved so the
/// dependency chains overlap), with `f = a Phi + b J` formed on the fly.
fn xsolve_rows(rows: &mut [f32], inj: Option<&[f32]>, nx: usize, a: f32, b: f32, t: &Thomas) {
    let nrows = rows.len() / nx;
    let r = t.r;
    let (m, cp) = (&t.m[..nx], &t.cp[..nx]);
    let mut prev = [0f32; XSOLVE_ROWS];
    // Forward sweep.
    for i in 0..nx {
        let mi = m[i];
        for k in 0..nrows {
            let idx = k * nx + i;
            let f = match inj {
                Some(j) => a * rows[idx] + b * j[idx],
                None => a * rows[idx],
            };
            let v = flush((f + r * prev[k]) * mi);
            rows[idx] = v;
            prev[k] = v;
        }
    }
    // Backward sweep.
    for i in (0..nx.saturating_sub(1)).rev() {
        let ci = cp[i];
        for k in 0..nrows {
            let idx = k * nx + i;
            rows[idx] = flush(rows[idx] + ci * rows[idx + 1]);
        }
    }
}

/// Backward-Euler y-solve of one strip of columns, sweeping rows (contiguous within the strip).
fn ysolve_strip(s: &mut Strip<'_>, t: &Thomas) {
    let ny = s.ny;
    let r = t.r;
    let (m, cp) = (&t.m[..ny], &t.cp[..ny]);
    for v in s.row(0) {
        *v = flush(*v * m[0]);
    }
    for j in 1..ny {
        let mj = m[j];
        let (lo, cur) = s.rows2(j - 1, j);
        for (c, &l) in cur.iter_mut().zip(lo.iter()) {
            *c = flush((*c + r * l) * mj);
        }
    }
    for j in (0..ny - 1).rev() {
        let cj = cp[j];
        let (hi, cur) = s.rows2(j + 1, j);
        for (c, &h) in cur.iter_mut().zip(hi.iter()) {
            *c = flush(*c + cj * h);
        }
    }
}

/// Upwind advection along x by Courant number `c` (|c| <= 1), in place, no-flux walls.
fn advect_x(values: &mut [f32], nx: usize, c: f32, parallel: bool) {
    let f = |row: &mut [f32]| {
        if c > 0.0 {
            // Face flux c * phi_i from i to i + 1; the last cell sends nothing.
            let l = nx - 1;
            row[l] = flush(row[l] + c * row[l - 1]);
            for i in (1..l).rev() {
                row[i] = flush(row[i] * (1.0 - c) + c * row[i - 1]);
            }
            row[0] = flush(row[0] * (1.0 - c));
        } else {
            let c = -c;
            row[0] = flush(row[0] + c * row[1]);
            for i in 1..nx - 1 {
                row[i] = flush(row[i] * (1.0 - c) + c * row[i + 1]);
            }
            row[nx - 1] = flush(row[nx - 1] * (1.0 - c));
        }
    };
    if parallel {
        values.par_chunks_mut(nx).for_each(f);
    } else {
        values.chunks_mut(nx).for_each(f);
    }
}

/// Upwind advection along y by Courant number `c` (|c| <= 1), in place, no-flux walls.
fn advect_y(values: &mut [f32], nx: usize, ny: usize, c: f32, parallel: bool) {
    let grid = StripGrid::new(values, nx, ny);
    grid.for_each_strip(parallel, |s| {
        let axpy = |dst: &mut [f32], src: &[f32], keep: f32| {
            for (d, &s) in dst.iter_mut().zip(src) {
                *d = flush(*d * keep + c.abs() * s);
            }
        };
        if c > 0.0 {
            let (lo, top) = s.rows2(ny - 2, ny - 1);
            axpy(top, lo, 1.0);
            for j in (1..ny - 1).rev() {
                let (lo, cur) = s.rows2(j - 1, j);
                axpy(cur, lo, 1.0 - c);
            }
            s.row(0).iter_mut().for_each(|v| *v = flush(*v * (1.0 - c)));
        } else {
            let ca = -c;
            let (hi, bot) = s.rows2(1, 0);
            axpy(bot, hi, 1.0);
            for j in 1..ny - 1 {
                let (hi, cur) = s.rows2(j + 1, j);
                axpy(cur, hi, 1.0 - ca);
            }
            s.row(ny - 1)
                .iter_mut()
                .for_each(|v| *v = flush(*v * (1.0 - ca)));
        }
    });
}

/// A row-major grid split into strips of columns that may be processed concurrently.
struct StripGrid<'a> {
    ptr: SyncPtr,
    nx: usize,
    ny: usize,
    _borrow: std::marker::PhantomData<&'a mut [f32]>,
}

#[derive(Clone, Copy)]
struct SyncPtr(*mut f32);
// SAFETY: the pointer is only used to build slices of disjoint column strips (see `Strip`).
unsafe impl Send for SyncPtr {}
unsafe impl Sync for SyncPtr {}

/// Columns `[i0, i0 + width)` of every row of a [`StripGrid`].
struct Strip<'a> {
    ptr: SyncPtr,
    nx: usize,
    ny: usize,
    i0: usize,
    width: usize,
    _borrow: std::marker::PhantomData<&'a mut [f32]>,
}

impl<'a> StripGrid<'a> {
    fn new(values: &'a mut [f32], nx: usize, ny: usize) -> Self {
        assert_eq!(values.len(), nx * ny);
        StripGrid {
            ptr: SyncPtr(values.as_mut_ptr()),
            nx,
            ny,
            _borrow: std::marker::PhantomData,
        }
    }

    fn for_each_strip(self, parallel: bool, f: impl Fn(&mut Strip<'_>) + Sync + Send) {
        let (nx, ny, ptr) = (self.nx, self.ny, self.ptr);
        let nstrips = nx.div_ceil(STRIP_COLS);
        let run = |k: usize| {
            let i0 = k * STRIP_COLS;
            let width = STRIP_COLS.min(nx - i0);
            // Each strip owns its columns exclusively: no two strips alias.
            let mut s = Strip {
                ptr,
                nx,
                ny,
                i0,
                width,
                _borrow: std::marker::PhantomData,
            };
            f(&mut s);
        };
        if parallel {
            (0..nstrips).into_par_iter().for_each(run);
        } else {
            (0..nstrips).for_each(run);
        }
    }
}

impl Strip<'_> {
    fn row(&mut self, j: usize) -> &mut [f32] {
        assert!(j < self.ny);
        // SAFETY: in bounds (j < ny, i0 + width <= nx); the strip holds its columns exclusively and the
        // returned slice borrows `self` mutably.
        unsafe { std::slice::from_raw_parts_mut(self.ptr.0.add(j * self.nx + self.i0), self.width) }
    }

    /// Row `other` (read) and row `j` (write) of the strip; `other != j`.
    fn rows2(&mut self, other: usize, j: usize) -> (&[f32], &mut [f32]) {
        assert!(other < self.ny && j < self.ny && other != j);
        // SAFETY: distinct rows of the strip do not overlap; both in bounds; borrows of `self`.
        unsafe {
            let o =
                std::slice::from_raw_parts(self.ptr.0.add(other * self.nx + self.i0), self.width);
            let c =
                std::slice::from_raw_parts_mut(self.ptr.0.add(j * self.nx + self.i0), self.width);
            (o, c)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn thomas_solves_the_system() {
        let n = 7;
        let r = 3.5f32;
        let t = Thomas::new(n, r);
        let f: Vec<f32> = (0..n).map(|i| (i * i) as f32 + 1.0).collect();
        let mut u = f.clone();
        xsolve_rows(&mut u, None, n, 1.0, 0.0, &t);
        for i in 0..n {
            let l = if i > 0 { u[i - 1] } else { u[i] };
            let rr = if i + 1 < n { u[i + 1] } else { u[i] };
            let lhs = u[i] - r * (l + rr - 2.0 * u[i]);
            assert!(
                (lhs - f[i]).abs() < 1e-4 * f[i].max(1.0),
                "{i}: {lhs} vs {}",
                f[i]
            );
        }
        let s: f32 = u.iter().sum();
        let s0: f32 = f.iter().sum();
        assert!((s - s0).abs() < 1e-4 * s0);
    }

    #[test]
    fn avx2_band_matches_baseline_bit_for_bit() {
        let (nx, rows) = (203, 9);
        let band0: Vec<f32> = (0..nx * rows)
            .map(|k| ((k * 7919) % 1000) as f32 * 0.013)
            .collect();
        let below: Vec<f32> = (0..nx).map(|k| k as f32 * 0.1).collect();
        let inj: Vec<f32> = (0..nx * (rows + 5)).map(|k| (k % 5) as f32).collect();
        for inj in [None, Some(&inj[..])] {
            let args = BandArgs {
                j0: 2,
                below: Some(&below),
                above: None,
                inj,
                nx,
                a: 0.97,
                b: 0.031,
                r: 0.23,
            };
            let mut base = band0.clone();
            explicit_band(&mut base, &args);
            let mut fast = band0.clone();
            explicit_band_dispatch(&mut fast, &args);
            assert!(
                base.iter()
                    .zip(&fast)
                    .all(|(x, y)| x.to_bits() == y.to_bits())
            );
        }
    }

    #[test]
    fn lerp_index_clamps() {
        assert_eq!(lerp_index(-3.0, 5), (0, 0, 0.0));
        assert_eq!(lerp_index(10.0, 5), (4, 4, 0.0));
        assert_eq!(lerp_index(1.25, 5), (1, 2, 0.25));
        assert_eq!(lerp_index(0.7, 1), (0, 0, 0.0));
    }

    /// The deposit as first written: every cell of the bounding box weighed.
    fn deposit_whole_box(
        g: &mut GridField,
        kernel: &crate::field::Kernel,
        a: Vec2,
        b: Vec2,
        amount: f32,
    ) {
        let GridSpec { nx, ny, cell } = *g.spec();
        let support = kernel.support();
        let (i0, i1) = g
            .spec
            .cell_range(a.x.min(b.x) - support, a.x.max(b.x) + support, nx);
        let (j0, j1) = g
            .spec
            .cell_range(a.y.min(b.y) - support, a.y.max(b.y) + support, ny);
        let (ab, len2) = (b - a, (b - a).length_squared());
        for j in j0..j1 {
            for i in i0..i1 {
                let p = Vec2::new((i as f32 + 0.5) * cell, (j as f32 + 0.5) * cell);
                let dist = segment_distance(p, a, ab, len2);
                if dist <= support {
                    let w = kernel.weight(dist);
                    if w != 0.0 {
                        g.values[j * nx + i] += amount * w;
                    }
                }
            }
        }
    }

    proptest::proptest! {
        /// Deposits that weigh only the cells near the segment, in bands or whole, leave every cell
        /// bit for bit as weighing the whole bounding box does.
        #[test]
        fn deposits_equal_the_whole_box(
            shape in 0usize..3,
            size in 0.0005f32..0.05,
            cell in proptest::sample::select(vec![0.003f32, 0.005, 0.01, 0.0137]),
            a in (-0.05f32..0.65, -0.05f32..0.45),
            step in (-0.06f32..0.06, -0.06f32..0.06),
            bands in 1usize..5,
        ) {
            use crate::field::Kernel;
            let kernel = match shape {
                0 => Kernel::Disc { radius: size },
                1 => Kernel::Cone { radius: size },
                _ => Kernel::Gaussian { sigma: size / 3.0 },
            };
            let spec = GridSpec::covering(Vec2::new(0.6, 0.4), cell);
            let (a, b) = (Vec2::new(a.0, a.1), Vec2::new(a.0 + step.0, a.1 + step.1));
            let mut want = GridField::new(spec, GridParams::default());
            deposit_whole_box(&mut want, &kernel, a, b, 1.7);
            let mut whole = GridField::new(spec, GridParams::default());
            whole.deposit_segment(&kernel, a, b, 1.7);
            let mut banded = GridField::new(spec, GridParams::default());
            let rows = spec.ny.div_ceil(bands);
            for mut band in banded.bands_mut(rows) {
                band.deposit_segment(&kernel, a, b, 1.7);
            }
            let bits = |g: &GridField| g.values().iter().map(|v| v.to_bits()).collect::<Vec<_>>();
            proptest::prop_assert_eq!(bits(&whole), bits(&want));
            proptest::prop_assert_eq!(bits(&banded), bits(&want));
        }
    }
}
