//! Wind: first-order upwind advection in conservative flux form with no-flux walls.
use super::flush;
use super::strips::StripGrid;
use rayon::prelude::*;

/// Upwind advection along x by Courant number `c` (|c| <= 1), in place, no-flux walls.
pub(super) fn advect_x(values: &mut [f32], nx: usize, c: f32, parallel: bool) {
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
pub(super) fn advect_y(values: &mut [f32], nx: usize, ny: usize, c: f32, parallel: bool) {
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
