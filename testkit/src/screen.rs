//! The screen renderer as it was before its lookup tables and vector kernels: every pixel of eq. (1)
//! interpolated on its own. The reference the renderer's tests and the live tick's bench compare
//! today's renderer with, byte for byte.
use colcos_sim::Vec2;
use colcos_sim::field::{FieldModel, Pheromone};
use colcos_sim::screen::{ScreenSpec, to_level};

/// The grid sampler's clamped interpolation index, as it was when the reference was written (NaN goes
/// to the first cell).
fn lerp_index(f: f32, n: usize) -> (usize, usize, f32) {
    if n <= 1 || f.is_nan() || f <= 0.0 {
        return (0, 0, 0.0);
    }
    if f >= (n - 1) as f32 {
        return (n - 1, n - 1, 0.0);
    }
    let i0 = (f as usize).min(n - 2);
    (i0, i0 + 1, f - i0 as f32)
}

/// A `w` x `h` RGB image (row 0 at the top) of the pheromones on `screen`, rows drawn on one scoped
/// thread per core.
pub fn reference_render(
    pheromones: &[Pheromone],
    screen: &ScreenSpec,
    w: usize,
    h: usize,
) -> Vec<u8> {
    let mut img = vec![0u8; 3 * w * h];
    let (px, py) = (screen.size[0] / w as f32, screen.size[1] / h as f32);
    let xs: Vec<f32> = (0..w).map(|i| (i as f32 + 0.5) * px).collect();
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    let per_thread = h.div_ceil(threads).max(1);
    let draw_row = |row: usize, out: &mut [u8]| {
        let y = (h - 1 - row) as f32 * py + 0.5 * py;
        let mut acc = vec![[0f32; 3]; w];
        let mut vals = vec![0f32; w];
        for ph in pheromones {
            match &ph.model {
                FieldModel::Grid(g) => {
                    let s = g.spec();
                    let (j0, j1, ty) = lerp_index(y / s.cell - 0.5, s.ny);
                    let v = g.values();
                    let (lo, hi) = (&v[j0 * s.nx..][..s.nx], &v[j1 * s.nx..][..s.nx]);
                    for (o, &x) in vals.iter_mut().zip(&xs) {
                        let (i0, i1, tx) = lerp_index(x / s.cell - 0.5, s.nx);
                        let a = lo[i0] + (lo[i1] - lo[i0]) * tx;
                        let b = hi[i0] + (hi[i1] - hi[i0]) * tx;
                        *o = a + (b - a) * ty;
                    }
                }
                FieldModel::Gaussian(_) => {
                    for (o, &x) in vals.iter_mut().zip(&xs) {
                        *o = ph.value_at(Vec2::new(x, y));
                    }
                }
            }
            for (a, &v) in acc.iter_mut().zip(&vals) {
                for (a, k) in a.iter_mut().zip(ph.colour) {
                    *a += k * v;
                }
            }
        }
        for (o, a) in out.chunks_exact_mut(3).zip(&acc) {
            o.copy_from_slice(&a.map(to_level));
        }
    };
    std::thread::scope(|scope| {
        for (k, band) in img.chunks_mut(3 * w * per_thread).enumerate() {
            let draw_row = &draw_row;
            scope.spawn(move || {
                for (r, out) in band.chunks_mut(3 * w).enumerate() {
                    draw_row(k * per_thread + r, out);
                }
            });
        }
    });
    img
}
