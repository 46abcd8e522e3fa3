//! Eq. (1) at a robot's four colour-sensor footprints (36 screen samples), the hot path of sensing:
//! the same values, bit for bit, as [`super::levels_at`] with one group of 36 points, in arrays padded
//! to whole 8-lane vectors. `levels_at` over `[Vec2; 36]` left a 4-point tail after every vector loop
//! (scalar code, a third of its instructions) and interleaved `x` and `y` in its loads; here the
//! points come as two coordinate arrays of [`LANES`], lanes past [`SAMPLES`] repeating lane 0, so
//! every loop is whole vectors and the padding changes no result (a repeated point adds no new
//! largest offset; its levels are never read).
use super::{ScreenSpec, pixel_centre_coord, to_level_u32};
use crate::field::{FieldModel, FrozenSources, GridSampler, NearbyPoints, Pheromone};

/// Samples of four footprints of nine points.
pub const SAMPLES: usize = 36;
/// [`SAMPLES`] rounded up to whole vectors of eight f32.
pub const LANES: usize = 40;

/// A robot's footprint samples, arena coordinates, structure of arrays: lanes `9 s .. 9 s + 9` are
/// sensor `s`'s; lanes from [`SAMPLES`] on repeat lane 0.
#[derive(Clone, Copy, Debug)]
pub struct FootprintSamples {
    pub xs: [f32; LANES],
    pub ys: [f32; LANES],
}

/// 8-bit levels (0..=255) at each sample, `[channel][lane]` (lanes past [`SAMPLES`]: padding).
pub type FootprintLevels = [[u32; LANES]; 3];

/// Eq. (1) at the samples: what `levels_at(.., points, 36)` gives for the first [`SAMPLES`] lanes.
pub fn footprint_levels(
    pheromones: &[Pheromone],
    frozen: &FrozenSources,
    screen: &ScreenSpec,
    samples: &FootprintSamples,
) -> FootprintLevels {
    #[cfg(target_arch = "x86_64")]
    if std::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU has AVX2.
        return unsafe { footprint_levels_avx2(pheromones, frozen, screen, samples) };
    }
    footprint_levels_portable(pheromones, frozen, screen, samples)
}

/// [`footprint_levels`] in AVX2 registers: no fused multiply-add, so the same bits as the portable
/// code (as for [`super::levels_at`]). For callers already compiled for AVX2 (no second dispatch).
///
/// # Safety
/// The CPU has AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[inline]
pub unsafe fn footprint_levels_avx2(
    pheromones: &[Pheromone],
    frozen: &FrozenSources,
    screen: &ScreenSpec,
    samples: &FootprintSamples,
) -> FootprintLevels {
    footprint_levels_with(
        pheromones,
        frozen,
        // SAFETY: the CPU has AVX2 (this function's contract).
        || unsafe { pixel_centres_avx2(screen, samples) },
        |xs, ys| {
            // SAFETY: the CPU has AVX2 (this function's contract).
            unsafe { NearbyPoints::of_padded_avx2(xs, ys, SAMPLES) }
        },
    )
}

/// The samples' pixel centres ([`pixel_centre_coord`] lane for lane) in AVX2 registers: the plain
/// conversion of `f.min(last)` kept the NaN handling of `min` (a compare and a blend a vector more),
/// which `f > 0` already excludes.
///
/// # Safety
/// The CPU has AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[inline]
unsafe fn pixel_centres_avx2(
    screen: &ScreenSpec,
    samples: &FootprintSamples,
) -> ([f32; LANES], [f32; LANES]) {
    use std::arch::x86_64::*;
    const { assert!(LANES.is_multiple_of(8)) };
    let pixel = screen.pixel_size();
    let last = |n: u32| (n.max(1) - 1).min(1 << 30) as f32;
    let axis = |v: &[f32; LANES], size: f32, n: u32| {
        let (size, last) = (_mm256_set1_ps(size), _mm256_set1_ps(last(n)));
        let mut out = [0f32; LANES];
        for k in (0..LANES).step_by(8) {
            // SAFETY: `k + 8 <= LANES`.
            unsafe {
                let f = _mm256_div_ps(_mm256_loadu_ps(v.as_ptr().add(k)), size);
                // `f > 0` (false for NaN), then `min(f, last)` of a number: `minps` gives it.
                let inside = _mm256_cmp_ps::<_CMP_GT_OQ>(f, _mm256_setzero_ps());
                let f = _mm256_and_ps(inside, _mm256_min_ps(f, last));
                // Truncation of a value in [0, 2^30]: what the integer conversion gives.
                let t = _mm256_round_ps::<{ _MM_FROUND_TO_ZERO | _MM_FROUND_NO_EXC }>(f);
                let centre = _mm256_mul_ps(_mm256_add_ps(t, _mm256_set1_ps(0.5)), size);
                _mm256_storeu_ps(out.as_mut_ptr().add(k), centre);
            }
        }
        out
    };
    let [nx, ny] = screen.resolution;
    (
        axis(&samples.xs, pixel.x, nx),
        axis(&samples.ys, pixel.y, ny),
    )
}

/// [`footprint_levels`] for any processor.
fn footprint_levels_portable(
    pheromones: &[Pheromone],
    frozen: &FrozenSources,
    screen: &ScreenSpec,
    samples: &FootprintSamples,
) -> FootprintLevels {
    let centres = || {
        let pixel = screen.pixel_size();
        let [nx, ny] = screen.resolution;
        (
            std::array::from_fn(|k| pixel_centre_coord(samples.xs[k], pixel.x, nx)),
            std::array::from_fn(|k| pixel_centre_coord(samples.ys[k], pixel.y, ny)),
        )
    };
    footprint_levels_with(pheromones, frozen, centres, |xs, ys| {
        NearbyPoints::new(&xs[..SAMPLES], &ys[..SAMPLES])
    })
}

/// The operations of [`super::levels_at_portable`] for one group of [`SAMPLES`] points, lane for lane,
/// but for products with a colour weight of zero, which add nothing to a level (see
/// [`Channels`]). `centres` gives the samples' pixel centres, `near` their [`NearbyPoints`] (the
/// same offsets in the first [`SAMPLES`] lanes either way).
#[inline(always)]
fn footprint_levels_with(
    pheromones: &[Pheromone],
    frozen: &FrozenSources,
    centres: impl FnOnce() -> ([f32; LANES], [f32; LANES]),
    near: impl FnOnce(&[f32; LANES], &[f32; LANES]) -> NearbyPoints<LANES>,
) -> FootprintLevels {
    let (xs, ys) = centres();
    let near = if frozen.is_empty() {
        None
    } else {
        Some(near(&xs, &ys))
    };
    let mut channels = Channels::default();
    // Made at the first grid pheromone: zeroing its arrays cost a tenth of a Gaussian-only call.
    let mut grid: Option<GridSampler<LANES>> = None;
    let mut values = [0f32; LANES];
    for (index, ph) in pheromones.iter().enumerate() {
        match &ph.model {
            FieldModel::Grid(g) => {
                if g.spec().is_empty() {
                    continue;
                }
                grid.get_or_insert_with(GridSampler::new)
                    .values(g, &xs, &ys, &mut values);
            }
            FieldModel::Gaussian(_) => {
                values = [0.0; LANES];
                if let Some(near) = &near {
                    for source in frozen.of(index) {
                        source.add_values_near(near, &xs, &ys, &mut values);
                    }
                }
            }
        }
        channels.add(&ph.colour, &values);
    }
    channels.levels()
}

/// Eq. (1)'s sums `sum_j k_j Phi_j` of the three channels. A product with `k = 0` is a zero (the level
/// is the same whatever its sign) or, where `Phi_j` is not finite, NaN, which makes the level 0:
/// zero weights are only added up (as `0 * Phi_j`, in `spoilt`) when their values are not all
/// finite, and a channel no pheromone colours reads 0 throughout.
struct Channels {
    sums: [[f32; LANES]; 3],
    coloured: [bool; 3],
    spoilt: Option<[[f32; LANES]; 3]>,
}

impl Default for Channels {
    fn default() -> Self {
        Channels {
            sums: [[0.0; LANES]; 3],
            coloured: [false; 3],
            spoilt: None,
        }
    }
}

impl Channels {
    #[inline(always)]
    fn add(&mut self, colour: &[f32; 3], values: &[f32; LANES]) {
        // The largest magnitude's bits (an integer maximum, which vectorises) below infinity's.
        let finite = || {
            let largest = values
                .iter()
                .fold(0u32, |m, v| m.max(v.to_bits() & !(1 << 31)));
            largest < f32::INFINITY.to_bits()
        };
        let mut checked = None;
        for c in 0..3 {
            let k = colour[c];
            if k != 0.0 {
                self.coloured[c] = true;
                for (a, &v) in self.sums[c].iter_mut().zip(values) {
                    *a += k * v;
                }
            } else if !*checked.get_or_insert_with(finite) {
                let spoilt = self.spoilt.get_or_insert([[0.0; LANES]; 3]);
                for (a, &v) in spoilt[c].iter_mut().zip(values) {
                    *a += k * v;
                }
            }
        }
    }

    /// The 8-bit levels: the sums and, where zero weights met values that are not finite, their NaN.
    #[inline(always)]
    fn levels(self) -> FootprintLevels {
        let mut out = [[0u32; LANES]; 3];
        for c in 0..3 {
            if !self.coloured[c] {
                continue;
            }
            let mut sum = self.sums[c];
            if let Some(spoilt) = &self.spoilt {
                for (a, &z) in sum.iter_mut().zip(&spoilt[c]) {
                    *a += z;
                }
            }
            for (o, &a) in out[c].iter_mut().zip(&sum) {
                *o = to_level_u32(a);
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::field::{GaussianField, GaussianSource, GridField, GridParams, GridSpec};
    use glam::Vec2;

    /// The padded footprint path gives `levels_at`'s levels bit for bit: grid and Gaussian fields
    /// (wide, narrow, correlated), points inside, on and beyond the panel's edges.
    #[test]
    fn footprint_levels_equal_levels_at() {
        use rand::{RngExt, SeedableRng};
        let mut rng = rand::rngs::SmallRng::seed_from_u64(9);
        let spec = GridSpec::new(60, 34, 0.024);
        let mut g = GridField::new(spec, GridParams::default());
        // A few infinite and NaN cells: a channel no pheromone colours (blue) still reads 0 there.
        g.values_mut().iter_mut().for_each(|v| {
            *v = match rng.random_range(0..200) {
                0 => f32::INFINITY,
                1 => f32::NAN,
                _ => rng.random_range(0.0..1.5),
            }
        });
        let source = |sigma: f32, rho: f32, centre: Vec2| GaussianSource {
            k: 0.8,
            sigma_x: sigma,
            sigma_y: sigma * 1.3,
            rho,
            evaporation: 5.0,
            centre,
            start: 0.0,
        };
        let gaussian = GaussianField {
            sources: vec![
                source(0.4, 0.0, Vec2::new(0.7, 0.4)),
                source(0.05, 0.3, Vec2::new(0.3, 0.2)),
                source(0.003, -0.2, Vec2::new(1.0, 0.6)),
            ],
            time: 0.7,
        };
        let ph =
            crate::field::grid_and_gaussian(g, gaussian, [[180.0, 20.0, 0.0], [0.0, 255.0, 0.0]]);
        let screen = ScreenSpec::default();
        let frozen = FrozenSources::new(&ph);
        let offsets: [Vec2; 9] = std::array::from_fn(|k| {
            if k == 0 {
                Vec2::ZERO
            } else {
                0.00105 * Vec2::from_angle(std::f32::consts::TAU * (k - 1) as f32 / 8.0)
            }
        });
        for trial in 0..400 {
            let c = Vec2::new(rng.random_range(-0.05..1.5), rng.random_range(-0.05..0.85));
            let pose = crate::robot::Pose {
                pos: c,
                heading: trial as f32 * 0.37,
            };
            let sensors = crate::sensors::sensor_positions(&pose, 0.015);
            let points: [Vec2; SAMPLES] = std::array::from_fn(|j| sensors[j / 9] + offsets[j % 9]);
            let fields = super::super::ScreenFields {
                pheromones: &ph,
                frozen: &frozen,
                screen: &screen,
            };
            let want = super::super::levels_at(&fields, &points, SAMPLES);
            let samples = FootprintSamples {
                xs: std::array::from_fn(|j| points[if j < SAMPLES { j } else { 0 }].x),
                ys: std::array::from_fn(|j| points[if j < SAMPLES { j } else { 0 }].y),
            };
            let got = footprint_levels(&ph, &frozen, &screen, &samples);
            let portable = footprint_levels_portable(&ph, &frozen, &screen, &samples);
            for c in 0..3 {
                assert_eq!(got[c][..SAMPLES], want[c][..], "channel {c}, trial {trial}");
                assert_eq!(
                    portable[c][..SAMPLES],
                    want[c][..],
                    "channel {c}, trial {trial}"
                );
            }
        }
    }
}
