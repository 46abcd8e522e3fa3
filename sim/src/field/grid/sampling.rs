//! Bilinear sampling of a grid field.
use super::{GridField, GridSpec};
use glam::Vec2;

impl GridField {
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lerp_index_clamps() {
        assert_eq!(lerp_index(-3.0, 5), (0, 0, 0.0));
        assert_eq!(lerp_index(10.0, 5), (4, 4, 0.0));
        assert_eq!(lerp_index(1.25, 5), (1, 2, 0.25));
        assert_eq!(lerp_index(0.7, 1), (0, 0, 0.0));
    }
}
