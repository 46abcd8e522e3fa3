//! Explicit diffusion: the symmetric 5-point Laplacian, fused with evaporation and injection, in place.
use super::{GridField, GridSpec, flush};
use rayon::prelude::*;

impl GridField {
    /// `n` explicit sub-steps of diffusion number `r`; the first is fused with evaporation and injection.
    pub(super) fn explicit(&mut self, a: f32, b: f32, r: f32, n: usize, parallel: bool) {
        let GridSpec { nx, ny, .. } = self.spec;
        for k in 0..n {
            let inj = if k == 0 {
                self.injection.as_deref()
            } else {
                None
            };
            let (a, b) = if k == 0 { (a, b) } else { (1.0, 0.0) };
            explicit_pass(
                &mut self.values,
                &mut self.explicit_rows,
                inj,
                nx,
                ny,
                a,
                b,
                r,
                parallel,
            );
        }
    }
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
    rows: &mut ExplicitRows,
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
    let band_rows = ny.div_ceil(nb).max(1);
    let nb = ny.div_ceil(band_rows).max(1);
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
    // Halo rows (psi of the old values) just outside each band, and each band's three working rows:
    // buffers kept between passes, so a running field allocates nothing.
    rows.bands.resize_with(nb, BandRows::default);
    for (k, band) in rows.bands.iter_mut().enumerate() {
        let (j0, j1) = (k * band_rows, ((k + 1) * band_rows).min(ny));
        band.has_below = j0 > 0;
        if band.has_below {
            psi_into(values, j0 - 1, &mut band.below);
        }
        band.has_above = j1 < ny;
        if band.has_above {
            psi_into(values, j1, &mut band.above);
        }
    }
    let run = |(k, (band, work)): (usize, (&mut [f32], &mut BandRows))| {
        let args = BandArgs {
            j0: k * band_rows,
            below: work.has_below.then_some(&work.below[..]),
            above: work.has_above.then_some(&work.above[..]),
            inj,
            nx,
            a,
            b,
            r,
        };
        explicit_band_dispatch(band, &args, &mut work.rows);
    };
    let bands = &mut rows.bands[..nb];
    if parallel {
        values
            .par_chunks_mut((band_rows * nx).max(1))
            .zip(bands.par_iter_mut())
            .enumerate()
            .for_each(run);
    } else {
        values
            .chunks_mut((band_rows * nx).max(1))
            .zip(bands.iter_mut())
            .enumerate()
            .for_each(run);
    }
}

/// The row buffers of [`explicit_pass`], kept by the field between passes.
#[derive(Default)]
pub(super) struct ExplicitRows {
    bands: Vec<BandRows>,
}

/// One band's buffers: psi of the rows just below and above it (when it has them) and the three rows
/// [`explicit_band`] works in.
#[derive(Default)]
struct BandRows {
    below: Vec<f32>,
    above: Vec<f32>,
    has_below: bool,
    has_above: bool,
    rows: [Vec<f32>; 3],
}

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
fn explicit_band_dispatch(band: &mut [f32], args: &BandArgs<'_>, work: &mut [Vec<f32>; 3]) {
    #[cfg(target_arch = "x86_64")]
    {
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU supports AVX2 (checked just above).
            unsafe { explicit_band_avx2(band, args, work) };
            return;
        }
    }
    explicit_band(band, args, work);
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
/// # Safety
/// The CPU must support AVX2.
unsafe fn explicit_band_avx2(band: &mut [f32], args: &BandArgs<'_>, work: &mut [Vec<f32>; 3]) {
    explicit_band(band, args, work);
}

/// One band of rows of [`explicit_pass`], in place, with `work` as its three row buffers.
#[inline(always)]
fn explicit_band(band: &mut [f32], args: &BandArgs<'_>, work: &mut [Vec<f32>; 3]) {
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
    let [mut prev, mut cur, mut next] = work.each_mut();
    psi_local(band, 0, cur);
    prev.clear();
    prev.extend_from_slice(below.unwrap_or(cur));
    for jl in 0..rows {
        if jl + 1 < rows {
            // psi of the row above is formed in the same loop as the stencil of this row.
            let (lo, hi) = band.split_at_mut((jl + 1) * nx);
            let q = inj.map(|jm| &jm[(j0 + jl + 1) * nx..(j0 + jl + 2) * nx]);
            next.resize(nx, 0.0);
            stencil_row_fused(cur, prev, &hi[..nx], q, a, b, next, &mut lo[jl * nx..], r);
        } else {
            next.clear();
            next.extend_from_slice(above.unwrap_or(cur));
            stencil_row(cur, next, prev, &mut band[jl * nx..(jl + 1) * nx], 1.0, r);
        }
        std::mem::swap(&mut prev, &mut cur);
        std::mem::swap(&mut cur, &mut next);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
            explicit_band(&mut base, &args, &mut Default::default());
            let mut fast = band0.clone();
            explicit_band_dispatch(&mut fast, &args, &mut Default::default());
            assert!(
                base.iter()
                    .zip(&fast)
                    .all(|(x, y)| x.to_bits() == y.to_bits())
            );
        }
    }
}
