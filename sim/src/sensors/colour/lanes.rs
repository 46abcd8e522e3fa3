//! The per-channel arithmetic of a robot's four colour sensors over lanes (counts from light, the
//! calibrated inverse), channel-major so that a 3x3 channel matrix is three multiply-adds over whole
//! lanes and the loops vectorise.
use super::{ColourSensor, pow_unit};
use crate::rng::SimRng;

impl ColourSensor {
    /// Counts of `S` sensors from their light per primary. The noise is drawn first, sensor by sensor
    /// in r, g, b order; the arithmetic then runs over the lanes of up to four sensors (vectorises).
    #[inline(always)]
    pub(super) fn counts_for_lights<const S: usize>(
        &self,
        light: &[[f32; 3]; S],
        rng: &mut SimRng,
    ) -> [[u16; 3]; S] {
        let mut out = [[0u16; 3]; S];
        for (light, out) in light.chunks(LANE_SENSORS).zip(out.chunks_mut(LANE_SENSORS)) {
            let counts = self.counts_of_spread(&spread(light), light.len(), rng);
            for (s, out) in out.iter_mut().enumerate() {
                *out = std::array::from_fn(|c| counts[lane(s, c)]);
            }
        }
        out
    }

    /// Counts of up to four sensors (`sensors`) from their light as [`spread`] lays it out, in lanes
    /// (`lane(s, c)`): [`ColourSensor::counts_for_lights`]' draws and arithmetic.
    #[inline(always)]
    pub(super) fn counts_of_spread(
        &self,
        [r, g, b]: &[[f32; LANES]; 3],
        sensors: usize,
        rng: &mut SimRng,
    ) -> [u16; LANES] {
        let p = &self.params;
        let scale = p.gain * p.integration_ms;
        let noise = self.noise_lanes(sensors, rng);
        let m = &self.crosstalk_lanes;
        let mut counts = [0u16; LANES];
        for i in 0..LANES {
            let signal = m[0][i] * r[i] + m[1][i] * g[i] + m[2][i] * b[i];
            let dark = self.dark[i / LANE_SENSORS];
            counts[i] = round_count(dark + scale * signal + noise[i]);
        }
        counts
    }

    /// The count noise of up to four sensors (`sensors`), in lanes (`lane(s, c)`), drawn sensor by
    /// sensor in r, g, b order: every read's random draws.
    #[inline(always)]
    fn noise_lanes(&self, sensors: usize, rng: &mut SimRng) -> [f32; LANES] {
        let sd = self.params.noise;
        let mut noise = [0.0f32; LANES];
        if sd > 0.0 {
            // The stream's state in a local copy for the draws, so that it can stay in registers
            // (the same draws in the same order).
            let (z, mut local) = (crate::rng::ziggurat(), rng.clone());
            for s in 0..sensors.min(LANE_SENSORS) {
                for c in 0..3 {
                    noise[lane(s, c)] = sd * crate::rng::normal_with(z, &mut local);
                }
            }
            *rng = local;
        }
        noise
    }

    /// The random draws of a robot's read ([`ColourSensor::read_robot`]) without the read: for a
    /// robot whose colour nobody reads, whose stream must go on as if it had been read.
    pub fn draw_read_noise(&self, rng: &mut SimRng) {
        self.noise_lanes(LANE_SENSORS, rng);
    }

    /// A robot's four sensors read from their footprints' level sums (as
    /// [`ColourSensor::footprint_sums_in`] gives them, or a GPU's sensing pass): the same counts,
    /// random draws and intensities as [`ColourSensor::read_robot`] at those footprints. A sum above
    /// the largest a footprint can have reads as that largest.
    pub fn read_robot_from_sums(
        &self,
        sums: &[[u32; 3]; 4],
        rng: &mut SimRng,
    ) -> ([[u16; 3]; 4], [[f32; 3]; 4]) {
        let lut = &self.light_by_sum;
        let last = lut.len() - 1;
        let light = sums.map(|sum| sum.map(|s| lut[(s as usize).min(last)]));
        let counts = self.counts_for_lights(&light, rng);
        (counts, self.intensities_inline(&counts))
    }

    /// Calibrated inverse: counts back to screen intensity in [0, 1] per channel.
    ///
    /// Subtracts the dark counts, divides by gain and integration time, undoes the crosstalk, clamps
    /// the light to [0, 1] and inverts the transfer curve: `intensity = light^(1 / gamma)`, which is
    /// `level / 255`. A saturated channel (65535) reads 1.
    pub fn intensity(&self, counts: [u16; 3]) -> [f32; 3] {
        self.intensities(&[counts])[0]
    }

    /// [`ColourSensor::intensity`] of `S` sensors, computed over the lanes of up to four sensors (the
    /// transfer curve's inverse by [`pow_unit`], so that it vectorises): the same values as `S` calls.
    pub fn intensities<const S: usize>(&self, counts: &[[u16; 3]; S]) -> [[f32; 3]; S] {
        self.intensities_inline(counts)
    }

    /// [`ColourSensor::intensities`], inlined into its caller (the robot read compiled for AVX2).
    #[inline(always)]
    pub(super) fn intensities_inline<const S: usize>(
        &self,
        counts: &[[u16; 3]; S],
    ) -> [[f32; 3]; S] {
        let p = &self.params;
        let scale = p.gain * p.integration_ms;
        let inv_gamma = if p.gamma > 0.0 { 1.0 / p.gamma } else { 1.0 };
        let mut out = [[0.0f32; 3]; S];
        for (counts, out) in counts
            .chunks(LANE_SENSORS)
            .zip(out.chunks_mut(LANE_SENSORS))
        {
            let mut signal = [[0.0f32; 3]; LANE_SENSORS];
            if scale > 0.0 {
                for (signal, counts) in signal.iter_mut().zip(counts) {
                    *signal = std::array::from_fn(|c| (counts[c] as f32 - self.dark[c]) / scale);
                }
            }
            let [r, g, b] = spread(&signal);
            let m = &self.inverse_lanes;
            let mut v = [0.0f32; LANES];
            for i in 0..LANES {
                let light = m[0][i] * r[i] + m[1][i] * g[i] + m[2][i] * b[i];
                // NaN (from an infinite gain) reads as no light.
                let light = if light > 0.0 { light.min(1.0) } else { 0.0 };
                v[i] = pow_unit(light, inv_gamma);
            }
            for (s, (out, counts)) in out.iter_mut().zip(counts).enumerate() {
                *out = std::array::from_fn(|c| {
                    if counts[c] == u16::MAX {
                        1.0
                    } else {
                        v[lane(s, c)]
                    }
                });
            }
        }
        out
    }
}

/// Sensors whose channels are computed together: a robot's four.
pub(super) const LANE_SENSORS: usize = 4;
/// Their channels, channel-major: lane `4 c + s` is channel `c` of sensor `s`, so that a 3x3 channel
/// matrix applies as three multiply-adds over whole lanes.
pub(super) const LANES: usize = 3 * LANE_SENSORS;

#[inline(always)]
pub(super) fn lane(sensor: usize, channel: usize) -> usize {
    LANE_SENSORS * channel + sensor
}

/// Each input channel of up to four sensors repeated in every channel's lanes: `[k][lane(s, c)]` is
/// `values[s][k]` (0 past the last sensor).
#[inline(always)]
fn spread(values: &[[f32; 3]]) -> [[f32; LANES]; 3] {
    let mut out = [[0.0f32; LANES]; 3];
    for (k, out) in out.iter_mut().enumerate() {
        for (s, v) in values.iter().enumerate().take(LANE_SENSORS) {
            for c in 0..3 {
                out[lane(s, c)] = v[k];
            }
        }
    }
    out
}

/// A 3x3 channel matrix as lanes: `[k][lane(s, c)]` is `m[c][k]`.
pub(super) fn matrix_lanes(m: &[[f32; 3]; 3]) -> [[f32; LANES]; 3] {
    std::array::from_fn(|k| std::array::from_fn(|i| m[i / LANE_SENSORS][k]))
}

/// `raw.clamp(0, 65535).round() as u16` (NaN gives 0) without a libm `roundf` call: below 2^16 the
/// truncation and the fraction are exact in f32.
#[inline(always)]
pub(super) fn round_count(raw: f32) -> u16 {
    let c = if raw > 0.0 { raw.min(65535.0) } else { 0.0 };
    // SAFETY: `c` is in [0, 65535] (NaN went to 0 above), so the truncation is in range; the plain
    // conversion (not the saturating `as`) is what vectorises. Rounding up never passes 65535: a
    // fraction of one half needs `c >= t + 0.5`, so `t <= 65534`.
    let t = unsafe { c.to_int_unchecked::<i32>() };
    (t + i32::from(c - t as f32 >= 0.5)) as u16
}
