//! TCS34725-like colour sensor looking at the screen.
//!
//! Model: the screen emits `light_k = (level_k / 255)^gamma` in each primary; the sensor counts
//! `dark + gain * integration_ms * sum_k crosstalk[c][k] * light_k + noise * N(0, 1)`, clamped to
//! `0..=65535`. The calibrated inverse undoes all of it but the noise.
//!
//! Default gain: 1500 counts per unit light per ms. At the default 24 ms integration a full white
//! screen gives at most `30 + 1500 * 24 * 1.16 = 41,790` counts (the green row of the crosstalk matrix
//! sums to 1.16), well below saturation with room for noise; at 40 ms or more white saturates every
//! channel (`1500 * 40 * 1.11 > 65,535`), as a real TCS34725 does with too long an integration time.
use super::pow_unit;
#[cfg(test)]
use lanes::round_count;
use lanes::{LANES, matrix_lanes};

mod lanes;
mod robot;
mod view;
pub use view::ScreenView;

use crate::field::{FrozenSources, Pheromone};
use crate::rng::SimRng;
use crate::screen::{FOOTPRINT_LANES, FootprintLevels, FootprintSamples, ScreenSpec};
use glam::Vec2;
use serde::{Deserialize, Serialize};
use std::sync::{Arc, Mutex};

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ColourSensorParams {
    /// Radius of the patch of screen a sensor averages, m.
    pub footprint_radius: f32,
    /// Display transfer curve: emitted light = (level / 255) ^ gamma.
    pub gamma: f32,
    /// 3x3 channel crosstalk: counts_c = sum_k crosstalk[c][k] * light_k.
    pub crosstalk: [[f32; 3]; 3],
    /// Counts per unit light per ms of integration.
    pub gain: f32,
    /// Integration time, ms.
    pub integration_ms: f32,
    /// Dark counts added to every channel.
    pub dark_counts: f32,
    /// Standard deviation of the count noise (counts).
    pub noise: f32,
    /// Each robot reads the screen through its own fitted sensors: the file `[rig]
    /// colour_calibration` names, robot i matched by its radio address (the rig's sensors in the
    /// simulator). The file's models replace gamma, crosstalk, gain and dark counts.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub per_robot: bool,
}

impl Default for ColourSensorParams {
    fn default() -> Self {
        ColourSensorParams {
            footprint_radius: 0.0015,
            gamma: 2.2,
            crosstalk: [[1.0, 0.08, 0.03], [0.06, 1.0, 0.10], [0.02, 0.12, 1.0]],
            gain: 1500.0,
            integration_ms: 24.0,
            dark_counts: 30.0,
            noise: 8.0,
            per_robot: false,
        }
    }
}

/// Number of screen points a sensor averages: the centre and a ring of [`RING_POINTS`].
pub const RING_POINTS: usize = 8;
/// Radius of the sample ring as a fraction of the footprint radius.
pub const RING_FRACTION: f32 = 0.7;

/// A colour sensor model with its calibrated inverse.
#[derive(Clone, Debug)]
pub struct ColourSensor {
    /// Fixed at construction: the matrices below are derived from it.
    params: ColourSensorParams,
    /// Sample offsets of the footprint, m, relative to the sensor centre.
    offsets: [Vec2; RING_POINTS + 1],
    /// `offsets` of four footprints as [`FootprintSamples`] lanes (x, y): lane `j < 36` holds
    /// `offsets[j % 9]`, the padding lanes `offsets[0]`.
    offset_lanes: ([f32; FOOTPRINT_LANES], [f32; FOOTPRINT_LANES]),
    /// `light` of the mean level, indexed by the sum of the footprint's 8-bit levels (the transfer
    /// curve costs a table lookup instead of a `powf` per channel and reading). Shared by every
    /// sensor with the same `gamma`: a batch of a thousand worlds reads one table that stays in cache,
    /// not a thousand (9 KB each) that do not.
    light_by_sum: Arc<[f32]>,
    /// `params.crosstalk` and its inverse (identity if singular) as lanes ([`matrix_lanes`]).
    crosstalk_lanes: [[f32; LANES]; 3],
    inverse_lanes: [[f32; LANES]; 3],
    /// Dark counts per channel (each `params.dark_counts` unless fitted per channel).
    dark: [f32; 3],
}

/// The table of [`ColourSensor::light`] by footprint level sum for `gamma`, built once per process and
/// value of `gamma`.
fn shared_light_table(gamma: f32) -> Arc<[f32]> {
    static TABLES: Mutex<Vec<(u32, Arc<[f32]>)>> = Mutex::new(Vec::new());
    let key = gamma.to_bits();
    // A poisoned lock only means another thread panicked while pushing: the list is still valid.
    let mut tables = TABLES.lock().unwrap_or_else(|e| e.into_inner());
    if let Some((_, t)) = tables.iter().find(|(k, _)| *k == key) {
        return t.clone();
    }
    let table: Arc<[f32]> = (0..=255 * FOOTPRINT_POINTS as u32)
        .map(|sum| light_of_level(mean_level(sum), gamma))
        .collect();
    tables.push((key, table.clone()));
    table
}

/// Samples in one footprint.
const FOOTPRINT_POINTS: usize = RING_POINTS + 1;

/// Inverse of a 3x3 matrix, computed in f64; `None` when (nearly) singular.
pub fn invert3(m: &[[f32; 3]; 3]) -> Option<[[f32; 3]; 3]> {
    let a = |r: usize, c: usize| m[r][c] as f64;
    let cof = |r: usize, c: usize| {
        let (r1, r2) = ((r + 1) % 3, (r + 2) % 3);
        let (c1, c2) = ((c + 1) % 3, (c + 2) % 3);
        a(r1, c1) * a(r2, c2) - a(r1, c2) * a(r2, c1)
    };
    let det = a(0, 0) * cof(0, 0) + a(0, 1) * cof(0, 1) + a(0, 2) * cof(0, 2);
    if !det.is_finite() || det.abs() < 1e-9 {
        return None;
    }
    let mut inv = [[0.0f32; 3]; 3];
    for (r, row) in inv.iter_mut().enumerate() {
        for (c, v) in row.iter_mut().enumerate() {
            // inverse = adjugate / det, adjugate = transpose of the cofactors.
            *v = (cof(c, r) / det) as f32;
        }
    }
    Some(inv)
}

impl ColourSensor {
    pub fn new(params: ColourSensorParams) -> Self {
        Self::with_dark(params, [params.dark_counts; 3])
    }

    /// A sensor whose dark counts differ by channel (a fitted sensor: `dark` replaces
    /// `params.dark_counts`).
    pub fn with_dark(params: ColourSensorParams, dark: [f32; 3]) -> Self {
        const IDENTITY: [[f32; 3]; 3] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        let inverse = invert3(&params.crosstalk).unwrap_or(IDENTITY);
        let mut offsets = [Vec2::ZERO; RING_POINTS + 1];
        let ring = RING_FRACTION * params.footprint_radius.max(0.0);
        for (k, o) in offsets.iter_mut().skip(1).enumerate() {
            *o = ring * Vec2::from_angle(std::f32::consts::TAU * k as f32 / RING_POINTS as f32);
        }
        let offset_of_lane = |j: usize| {
            offsets[if j < 4 * FOOTPRINT_POINTS {
                j % FOOTPRINT_POINTS
            } else {
                0
            }]
        };
        ColourSensor {
            params,
            offsets,
            offset_lanes: (
                std::array::from_fn(|j| offset_of_lane(j).x),
                std::array::from_fn(|j| offset_of_lane(j).y),
            ),
            light_by_sum: shared_light_table(params.gamma),
            crosstalk_lanes: matrix_lanes(&params.crosstalk),
            inverse_lanes: matrix_lanes(&inverse),
            dark,
        }
    }

    /// The parameters the sensor was built with.
    pub fn params(&self) -> &ColourSensorParams {
        &self.params
    }

    /// Where on the screen the sensor at `p` samples, arena coordinates: `p` and a ring around it.
    pub fn sample_points(&self, p: Vec2) -> [Vec2; RING_POINTS + 1] {
        let mut points = self.offsets;
        for q in &mut points {
            *q += p;
        }
        points
    }

    /// Sum of the 8-bit screen levels (r, g, b) at the footprint's samples around `p`.
    pub fn footprint_sum(
        &self,
        pheromones: &[Pheromone],
        screen: &ScreenSpec,
        p: Vec2,
    ) -> [u32; 3] {
        self.footprint_sum_frozen(pheromones, &FrozenSources::new(pheromones), screen, p)
    }

    /// [`ColourSensor::footprint_sum`] with the Gaussian sources frozen once for many sensors.
    #[inline]
    pub fn footprint_sum_frozen(
        &self,
        pheromones: &[Pheromone],
        frozen: &FrozenSources,
        screen: &ScreenSpec,
        p: Vec2,
    ) -> [u32; 3] {
        self.footprint_sums(pheromones, frozen, screen, &[p])[0]
    }

    /// [`ColourSensor::footprint_sum_frozen`] of `S` sensors at once (a robot's four): their
    /// footprints' `S x 9` screen samples are evaluated together, which vectorises.
    #[inline]
    pub fn footprint_sums<const S: usize>(
        &self,
        pheromones: &[Pheromone],
        frozen: &FrozenSources,
        screen: &ScreenSpec,
        sensors: &[Vec2; S],
    ) -> [[u32; 3]; S] {
        let view = ScreenView {
            pheromones,
            frozen,
            screen,
            printed: None,
        };
        self.footprint_sums_in(&view, sensors)
    }

    /// [`ColourSensor::footprint_sums`] of the screen `view` shows (printed obstacles drawn over the
    /// pheromones, if it has any).
    #[inline]
    pub fn footprint_sums_in<const S: usize>(
        &self,
        view: &ScreenView,
        sensors: &[Vec2; S],
    ) -> [[u32; 3]; S] {
        self.footprint_sums_with(sensors, |samples| view.levels(samples))
    }

    /// [`ColourSensor::footprint_sums_in`] with the screen's levels from `levels` (one of
    /// [`ScreenView::levels`]'s implementations), inlined into its caller.
    #[inline(always)]
    fn footprint_sums_with<const S: usize>(
        &self,
        sensors: &[Vec2; S],
        levels: impl Fn(&FootprintSamples) -> FootprintLevels,
    ) -> [[u32; 3]; S] {
        // Const-generic array lengths cannot be computed (`S * 9`) on stable Rust: up to four sensors
        // go through one fixed-size batch, more in batches of four.
        const BATCH: usize = 4;
        let mut sums = [[0u32; 3]; S];
        for (sensors, sums) in sensors.chunks(BATCH).zip(sums.chunks_mut(BATCH)) {
            let levels = levels(&self.footprint_samples(sensors));
            // A footprint's nine levels as eight (one vector reduction) and one.
            for (c, levels) in levels.iter().enumerate() {
                for (s, sum) in sums.iter_mut().enumerate() {
                    let first = s * FOOTPRINT_POINTS;
                    let eight: &[u32; 8] = levels[first..first + 8].try_into().expect("8 lanes");
                    sum[c] = eight.iter().sum::<u32>() + levels[first + 8];
                }
            }
        }
        sums
    }

    /// The screen samples of up to four sensors' footprints. Missing sensors of a short batch repeat
    /// the first: the batch stays one compact group of points (Gaussian sources take one `exp` per
    /// group, at its centroid). The padding lanes past the 36 samples repeat the first sample (see
    /// `FootprintSamples`).
    #[inline(always)]
    pub(super) fn footprint_samples(&self, sensors: &[Vec2]) -> FootprintSamples {
        // Each lane's sensor position (`fill` stores whole vectors), then `sample_points`' sum
        // `offset + p` over whole vectors.
        let (mut px, mut py) = (
            [sensors[0].x; FOOTPRINT_LANES],
            [sensors[0].y; FOOTPRINT_LANES],
        );
        for (s, p) in sensors.iter().enumerate().skip(1).take(3) {
            px[s * FOOTPRINT_POINTS..(s + 1) * FOOTPRINT_POINTS].fill(p.x);
            py[s * FOOTPRINT_POINTS..(s + 1) * FOOTPRINT_POINTS].fill(p.y);
        }
        let (ox, oy) = &self.offset_lanes;
        FootprintSamples {
            xs: std::array::from_fn(|j| ox[j] + px[j]),
            ys: std::array::from_fn(|j| oy[j] + py[j]),
        }
    }

    /// Mean 8-bit screen level (r, g, b) over the footprint around `p`, each in [0, 255].
    pub fn screen_levels(
        &self,
        pheromones: &[Pheromone],
        screen: &ScreenSpec,
        p: Vec2,
    ) -> [f32; 3] {
        self.footprint_sum(pheromones, screen, p).map(mean_level)
    }

    /// What the sensor at `p` reads: the same as `counts(screen_levels(..))`, with the transfer curve
    /// from a table. `frozen`: the Gaussian sources of `pheromones` as they are now
    /// ([`FrozenSources::new`]; a world refreshes one per step for all its sensors).
    pub fn read(
        &self,
        pheromones: &[Pheromone],
        frozen: &FrozenSources,
        screen: &ScreenSpec,
        p: Vec2,
        rng: &mut SimRng,
    ) -> [u16; 3] {
        self.read_all(pheromones, frozen, screen, &[p], rng)[0]
    }

    /// [`ColourSensor::read`] of `S` sensors (a robot's four) in order, their footprints evaluated
    /// together: the same random draws as `S` calls of `read`, and the same counts up to the f32
    /// rounding of Gaussian sources (which share one `exp` per batch of four footprints).
    pub fn read_all<const S: usize>(
        &self,
        pheromones: &[Pheromone],
        frozen: &FrozenSources,
        screen: &ScreenSpec,
        sensors: &[Vec2; S],
        rng: &mut SimRng,
    ) -> [[u16; 3]; S] {
        let view = ScreenView {
            pheromones,
            frozen,
            screen,
            printed: None,
        };
        self.read_all_in(&view, sensors, rng)
    }

    /// [`ColourSensor::read_all`] of the screen `view` shows (printed obstacles included).
    #[inline(always)]
    pub fn read_all_in<const S: usize>(
        &self,
        view: &ScreenView,
        sensors: &[Vec2; S],
        rng: &mut SimRng,
    ) -> [[u16; 3]; S] {
        let sums = self.footprint_sums_in(view, sensors);
        let lut = &self.light_by_sum;
        let light = sums.map(|sum| sum.map(|s| lut[s as usize]));
        self.counts_for_lights(&light, rng)
    }

    /// Counts of one sensor whose footprint level sum is `sum` (one of
    /// [`ColourSensor::footprint_sums_in`]'s), drawing what `read_all_in` of that sensor
    /// draws: sensors with models of their own share one batched footprint pass.
    pub fn counts_of_sum(&self, sum: [u32; 3], rng: &mut SimRng) -> [u16; 3] {
        let lut = &self.light_by_sum;
        self.counts_for_lights(&[sum.map(|s| lut[s as usize])], rng)[0]
    }

    /// Light emitted per primary, in [0, 1], for 8-bit levels.
    pub fn light(&self, levels: [f32; 3]) -> [f32; 3] {
        levels.map(|l| light_of_level(l, self.params.gamma))
    }

    /// Counts for the given mean screen levels: transfer curve, crosstalk, gain, integration, noise,
    /// saturation at 65535.
    pub fn counts(&self, levels: [f32; 3], rng: &mut SimRng) -> [u16; 3] {
        self.counts_for_lights(&[self.light(levels)], rng)[0]
    }
}

/// The display's transfer curve: light in [0, 1] of one primary at an 8-bit `level` (NaN gives 0).
fn light_of_level(level: f32, gamma: f32) -> f32 {
    let x = if level.is_nan() {
        0.0
    } else {
        (level / 255.0).clamp(0.0, 1.0)
    };
    x.powf(gamma)
}

/// Mean level of a footprint from the sum of its samples' levels.
fn mean_level(sum: u32) -> f32 {
    sum as f32 / FOOTPRINT_POINTS as f32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_round_like_libm_and_saturate() {
        for raw in [
            -5.0f32, 0.0, 0.49999997, 0.5, 1.5, 30.49, 30.5, 65534.5, 65535.0, 1e9,
        ] {
            let want = raw.clamp(0.0, 65535.0).round() as u16;
            assert_eq!(round_count(raw), want, "raw {raw}");
        }
        assert_eq!(round_count(f32::NAN), 0);
        let mut raw = 0.0f32;
        while raw < 70_000.0 {
            assert_eq!(round_count(raw), raw.clamp(0.0, 65535.0).round() as u16);
            raw += 0.37;
        }
    }

    /// An `nx x ny` grid of `cell` whose k-th value (row-major) is `value(k)`.
    pub(super) fn patterned_grid(
        nx: usize,
        ny: usize,
        cell: f32,
        value: impl Fn(usize) -> f32,
    ) -> crate::field::GridField {
        use crate::field::{GridField, GridParams, GridSpec};
        let mut g = GridField::new(GridSpec { nx, ny, cell }, GridParams::default());
        for (k, v) in g.values_mut().iter_mut().enumerate() {
            *v = value(k);
        }
        g
    }

    #[test]
    fn read_equals_counts_of_screen_levels() {
        use crate::field::{FieldModel, Pheromone};
        let g = patterned_grid(40, 20, 0.025, |k| (k as f32 * 0.37).sin().abs());
        let ph = [Pheromone {
            name: "p".into(),
            colour: [255.0, 90.0, 20.0],
            model: FieldModel::Grid(g),
        }];
        let screen = ScreenSpec::new([800, 400], [1.0, 0.5]);
        let s = ColourSensor::new(ColourSensorParams {
            gamma: 1.8,
            ..Default::default()
        });
        let (mut a, mut b) = (crate::rng::stream(3, 0, 0), crate::rng::stream(3, 0, 0));
        let mut lit = 0;
        for k in 0..500 {
            let p = Vec2::new(k as f32 * 0.0019, 0.25 + 0.2 * (k as f32 * 0.1).sin());
            let want = s.counts(s.screen_levels(&ph, &screen, p), &mut a);
            assert_eq!(
                s.read(&ph, &FrozenSources::new(&ph), &screen, p, &mut b),
                want,
                "at {p}"
            );
            lit += usize::from(want[0] > 1000);
        }
        assert!(lit > 100, "only {lit} readings see the field");
    }

    /// A grid field and two Gaussian sources, one narrow enough that footprints take their own `exp`:
    /// the fields the batched reads are checked on (here and in `robot`).
    pub(super) fn grid_and_gaussians(g: crate::field::GridField) -> [Pheromone; 2] {
        use crate::field::{GaussianField, GaussianSource};
        let source = |sigma: f32, centre: Vec2| GaussianSource {
            k: 0.3,
            sigma_x: sigma,
            sigma_y: sigma * 1.5,
            rho: 0.3,
            evaporation: 4.0,
            centre,
            start: 0.0,
        };
        let gaussian = GaussianField {
            sources: vec![
                source(0.3, Vec2::new(0.4, 0.3)),
                source(0.004, Vec2::new(0.8, 0.2)),
            ],
            time: 1.0,
        };
        crate::field::grid_and_gaussian(g, gaussian, [[200.0, 0.0, 60.0], [0.0, 255.0, 90.0]])
    }

    /// A robot's four sensors read together give what four single reads give, random draws included,
    /// on a grid field and Gaussian sources (one narrow enough that footprints take their own `exp`).
    #[test]
    fn read_all_equals_single_reads_in_order() {
        let ph = grid_and_gaussians(patterned_grid(60, 30, 0.02, |k| {
            (k as f32 * 0.61).cos().abs()
        }));
        let screen = ScreenSpec::new([1200, 600], [1.2, 0.6]);
        let s = ColourSensor::new(ColourSensorParams {
            noise: 3.0,
            ..Default::default()
        });
        let frozen = FrozenSources::new(&ph);
        let (mut a, mut b) = (crate::rng::stream(5, 0, 0), crate::rng::stream(5, 0, 0));
        for k in 0..300 {
            let c = Vec2::new(
                0.05 + k as f32 * 0.0037,
                0.3 + 0.25 * (k as f32 * 0.07).sin(),
            );
            let pose = crate::robot::Pose {
                pos: c,
                heading: k as f32 * 0.3,
            };
            let sensors = crate::sensors::sensor_positions(&pose, 0.015);
            let want = sensors.map(|p| s.read(&ph, &frozen, &screen, p, &mut a));
            assert_eq!(
                s.read_all(&ph, &frozen, &screen, &sensors, &mut b),
                want,
                "at {c}"
            );
        }
    }
}
