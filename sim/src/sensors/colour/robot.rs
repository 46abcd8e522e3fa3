//! A robot's four colour sensors read in one pass ([`ColourSensor::read_robot`]), sensing's hot path.
//! On AVX2 the footprints' level sums, the transfer curve's table and the counts stay in
//! channel-major vectors: a footprint's nine lanes summed by masked vector adds (twelve shuffled
//! reductions before), the table read by gathers, the light laid out in the counts' lanes directly.
#[cfg(target_arch = "x86_64")]
use super::lanes::{LANE_SENSORS, LANES, lane};
use super::{ColourSensor, FOOTPRINT_POINTS, ScreenView};
use crate::rng::SimRng;
use crate::screen::{FootprintLevels, FootprintSamples};
use glam::Vec2;

impl ColourSensor {
    /// A robot's four sensors read as [`ColourSensor::read_all_in`] does (the same random draws
    /// and counts), with their calibrated [`ColourSensor::intensities`]: the whole read compiled for
    /// AVX2 where the processor has it (no fused multiply-add, so the same bits), its twelve channels
    /// in wider registers.
    pub fn read_robot(
        &self,
        view: &ScreenView,
        sensors: &[Vec2; 4],
        rng: &mut SimRng,
    ) -> ([[u16; 3]; 4], [[f32; 3]; 4]) {
        #[cfg(target_arch = "x86_64")]
        if std::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU has AVX2.
            return unsafe { self.read_robot_avx2(view, sensors, rng) };
        }
        self.read_robot_portable(view, sensors, rng)
    }

    /// [`ColourSensor::read_robot`] for any processor.
    fn read_robot_portable(
        &self,
        view: &ScreenView,
        sensors: &[Vec2; 4],
        rng: &mut SimRng,
    ) -> ([[u16; 3]; 4], [[f32; 3]; 4]) {
        let counts = self.read_all_in(view, sensors, rng);
        (counts, self.intensities_inline(&counts))
    }

    /// [`ColourSensor::read_robot`] for AVX2.
    ///
    /// # Safety
    /// The CPU has AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn read_robot_avx2(
        &self,
        view: &ScreenView,
        sensors: &[Vec2; 4],
        rng: &mut SimRng,
    ) -> ([[u16; 3]; 4], [[f32; 3]; 4]) {
        use std::arch::x86_64::*;
        // SAFETY: the CPU has AVX2.
        let samples = unsafe { self.footprint_samples_avx2(sensors) };
        // SAFETY: the CPU has AVX2 (this function's contract).
        let levels = unsafe { view.levels_avx2(&samples) };
        // SAFETY: the CPU has AVX2.
        let sums = unsafe { footprint_sums_avx2(&levels) };
        // The light of each channel's four sums from the table, repeated in every channel's lanes
        // (what `spread` makes of sensor-major light). A level is at most 255, so a sum indexes the
        // table; the clamp only keeps the gather in bounds whatever the levels.
        let lut = &self.light_by_sum;
        let last = _mm_set1_epi32(lut.len().saturating_sub(1).min(i32::MAX as usize) as i32);
        let mut light = [[0f32; LANES]; 3];
        for (light, sums) in light.iter_mut().zip(sums) {
            // SAFETY: the indices are at most `lut.len() - 1` (`lut` is never empty); `light` holds
            // three groups of four lanes.
            unsafe {
                let l = _mm_i32gather_ps::<4>(lut.as_ptr(), _mm_min_epu32(sums, last));
                for group in 0..LANES / LANE_SENSORS {
                    _mm_storeu_ps(light.as_mut_ptr().add(LANE_SENSORS * group), l);
                }
            }
        }
        let lanes = self.counts_of_spread(&light, 4, rng);
        let counts = std::array::from_fn(|s| std::array::from_fn(|c| lanes[lane(s, c)]));
        (counts, self.intensities_inline(&counts))
    }
}

impl ColourSensor {
    /// [`ColourSensor::footprint_samples`] of four sensors: each lane's sensor coordinate picked from
    /// the four positions by one permute a vector (`fill`s and shuffles before), plus the offsets.
    ///
    /// # Safety
    /// The CPU has AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    #[inline]
    unsafe fn footprint_samples_avx2(&self, sensors: &[Vec2; 4]) -> FootprintSamples {
        use std::arch::x86_64::*;
        const { assert!(crate::screen::FOOTPRINT_LANES == 40) };
        // x0 y0 x1 y1 x2 y2 x3 y3.
        // SAFETY: four `Vec2` are eight consecutive f32.
        let xy = unsafe { _mm256_loadu_ps(sensors.as_ptr().cast()) };
        // Lane j of the samples is sensor j / 9's (padding lanes: sensor 0's).
        let sensor = |j: i32| if j < 36 { j / 9 } else { 0 };
        let (ox, oy) = &self.offset_lanes;
        let mut samples = FootprintSamples {
            xs: [0.0; 40],
            ys: [0.0; 40],
        };
        for k in 0..5 {
            let j = 8 * k as i32;
            let index = |odd: i32| {
                _mm256_setr_epi32(
                    2 * sensor(j) + odd,
                    2 * sensor(j + 1) + odd,
                    2 * sensor(j + 2) + odd,
                    2 * sensor(j + 3) + odd,
                    2 * sensor(j + 4) + odd,
                    2 * sensor(j + 5) + odd,
                    2 * sensor(j + 6) + odd,
                    2 * sensor(j + 7) + odd,
                )
            };
            let (px, py) = (
                _mm256_permutevar8x32_ps(xy, index(0)),
                _mm256_permutevar8x32_ps(xy, index(1)),
            );
            // SAFETY: lanes `8 k .. 8 k + 8` of 40.
            unsafe {
                let at = 8 * k;
                let x = _mm256_add_ps(_mm256_loadu_ps(ox.as_ptr().add(at)), px);
                let y = _mm256_add_ps(_mm256_loadu_ps(oy.as_ptr().add(at)), py);
                _mm256_storeu_ps(samples.xs.as_mut_ptr().add(at), x);
                _mm256_storeu_ps(samples.ys.as_mut_ptr().add(at), y);
            }
        }
        samples
    }
}

/// The level sums of four footprints of nine samples (lanes `9 s .. 9 s + 9` of each channel), as
/// one vector per channel holding the four sensors' sums. A footprint spans two vectors of eight
/// lanes: the lanes of each sensor are kept by masks and the four sensors' vectors reduced together
/// (integer sums: the order does not matter).
///
/// # Safety
/// The CPU has AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[inline]
unsafe fn footprint_sums_avx2(levels: &FootprintLevels) -> [std::arch::x86_64::__m128i; 3] {
    use std::arch::x86_64::*;
    const { assert!(FOOTPRINT_POINTS == 9 && crate::screen::FOOTPRINT_LANES == 40) };
    let lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
    // `below[n]`: lanes 0..n.
    let below = |n: i32| _mm256_cmpgt_epi32(_mm256_set1_epi32(n), lane);
    let (b1, b2, b3, b4) = (below(1), below(2), below(3), below(4));
    // A loop, not `levels.map` of a closure: whether LLVM inlined that closure changed with the
    // crate's code-generation units (14 M of the 770 M instructions of `benches/instructions.sh`).
    let mut sums = [_mm_setzero_si128(); 3];
    for (sum, channel) in sums.iter_mut().zip(levels) {
        let p = channel.as_ptr().cast::<__m256i>();
        // SAFETY: 40 lanes of u32 are five whole vectors.
        let (v0, v1, v2, v3, v4) = unsafe {
            (
                _mm256_loadu_si256(p),
                _mm256_loadu_si256(p.add(1)),
                _mm256_loadu_si256(p.add(2)),
                _mm256_loadu_si256(p.add(3)),
                _mm256_loadu_si256(p.add(4)),
            )
        };
        let s0 = _mm256_add_epi32(v0, _mm256_and_si256(b1, v1));
        let s1 = _mm256_add_epi32(_mm256_andnot_si256(b1, v1), _mm256_and_si256(b2, v2));
        let s2 = _mm256_add_epi32(_mm256_andnot_si256(b2, v2), _mm256_and_si256(b3, v3));
        let s3 = _mm256_add_epi32(_mm256_andnot_si256(b3, v3), _mm256_and_si256(b4, v4));
        // Pairwise sums: [s0 s1 s2 s3] per 128-bit half, then the halves added.
        let h = _mm256_hadd_epi32(_mm256_hadd_epi32(s0, s1), _mm256_hadd_epi32(s2, s3));
        *sum = _mm_add_epi32(_mm256_castsi256_si128(h), _mm256_extracti128_si256::<1>(h));
    }
    sums
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The AVX2 read gives the portable read's counts, intensities and random draws, on grid and
    /// Gaussian fields, near and beyond the panel's edges.
    #[test]
    fn avx2_read_equals_portable() {
        if !std::is_x86_feature_detected!("avx2") {
            return;
        }
        let ph = super::super::tests::grid_and_gaussians(super::super::tests::patterned_grid(
            60,
            34,
            0.024,
            |k| (k as f32 * 0.37).sin().abs() * 1.2,
        ));
        let screen = crate::screen::ScreenSpec::default();
        let frozen = crate::field::FrozenSources::new(&ph);
        let view = ScreenView {
            pheromones: &ph,
            frozen: &frozen,
            screen: &screen,
            printed: None,
        };
        let s = ColourSensor::new(super::super::ColourSensorParams {
            noise: 3.0,
            ..Default::default()
        });
        let (mut a, mut b) = (crate::rng::stream(8, 0, 0), crate::rng::stream(8, 0, 0));
        for k in 0..500 {
            let c = Vec2::new(
                -0.05 + k as f32 * 0.0031,
                0.4 + 0.45 * (k as f32 * 0.05).sin(),
            );
            let pose = crate::robot::Pose {
                pos: c,
                heading: k as f32 * 0.3,
            };
            let sensors = crate::sensors::sensor_positions(&pose, 0.015);
            // SAFETY: the CPU has AVX2 (checked above).
            let lanes = unsafe { s.footprint_samples_avx2(&sensors) };
            let want = s.footprint_samples(&sensors);
            assert_eq!((lanes.xs, lanes.ys), (want.xs, want.ys));
            // SAFETY: the CPU has AVX2 (checked above).
            let got = unsafe { s.read_robot_avx2(&view, &sensors, &mut a) };
            let want = s.read_robot_portable(&view, &sensors, &mut b);
            assert_eq!(got.0, want.0, "at {c}");
            assert_eq!(
                got.1.map(|v| v.map(f32::to_bits)),
                want.1.map(|v| v.map(f32::to_bits)),
                "at {c}"
            );
        }
        use rand::Rng;
        assert_eq!(a.next_u64(), b.next_u64());
    }
}
