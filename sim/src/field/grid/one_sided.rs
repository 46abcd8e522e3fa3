//! The paper's one-sided scheme, eq. (4), read conservatively (see [`DiffusionScheme::OneSided`]).
//!
//! [`DiffusionScheme::OneSided`]: super::DiffusionScheme::OneSided
use super::{BAND_ROWS, GridField, GridSpec, flush};
use crate::field::CellBuffer;
use rayon::prelude::*;

impl GridField {
    /// One sub-step of the conservative reading of eq. (4) with number `s = d dt / h^2`.
    pub(super) fn one_sided_pass(&mut self, s: f32, parallel: bool) {
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
