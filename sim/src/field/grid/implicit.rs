//! Backward-Euler diffusion split by direction: an x-solve per row (fused with evaporation and
//! injection), then a y-solve per strip of columns, both by the Thomas algorithm.
use super::strips::{Strip, StripGrid};
use super::{GridField, GridSpec, flush};
use rayon::prelude::*;

/// Rows solved together (interleaved) by the implicit x-solve.
const XSOLVE_ROWS: usize = 8;

/// Precomputed Thomas-algorithm coefficients for the backward-Euler system of one direction:
/// `(1 + 2r) u_i - r u_{i-1} - r u_{i+1} = f_i` with no-flux ends (`(1 + r) u_0 - r u_1 = f_0`).
/// Forward: `d_i = (f_i + r d_{i-1}) m_i`; backward: `u_i = d_i + cp_i u_{i+1}`. All coefficients are
/// positive, so the solve maps non-negative data to non-negative data.
#[derive(Clone, Debug)]
pub(super) struct Thomas {
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

impl GridField {
    /// Backward Euler split by direction: x-solve (fused with evaporation and injection), then y-solve.
    pub(super) fn implicit(&mut self, a: f32, b: f32, r: f32, parallel: bool) {
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
}
