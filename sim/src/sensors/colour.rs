//! TCS34725-like colour sensor looking at the screen.
use crate::field::Pheromone;
use crate::rng::SimRng;
use crate::screen::ScreenSpec;
use glam::Vec2;
use serde::{Deserialize, Serialize};

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
}

impl Default for ColourSensorParams {
    fn default() -> Self {
        ColourSensorParams {
            footprint_radius: 0.0015,
            gamma: 2.2,
            crosstalk: [[1.0, 0.08, 0.03], [0.06, 1.0, 0.10], [0.02, 0.12, 1.0]],
            gain: 20.0,
            integration_ms: 24.0,
            dark_counts: 30.0,
            noise: 8.0,
        }
    }
}

/// A colour sensor model with its calibrated inverse.
#[derive(Clone, Debug)]
pub struct ColourSensor {
    pub params: ColourSensorParams,
}

impl ColourSensor {
    pub fn new(_params: ColourSensorParams) -> Self {
        todo!()
    }
    /// Mean 8-bit screen level (r, g, b) over the footprint around `p`, each in [0, 255].
    pub fn screen_levels(&self, _pheromones: &[Pheromone], _screen: &ScreenSpec, _p: Vec2) -> [f32; 3] {
        todo!()
    }
    /// Counts for the given mean screen levels: transfer curve, crosstalk, gain, integration, noise,
    /// saturation at 65535.
    pub fn counts(&self, _levels: [f32; 3], _rng: &mut SimRng) -> [u16; 3] {
        todo!()
    }
    /// Calibrated inverse: counts back to screen intensity in [0, 1] per channel.
    pub fn intensity(&self, _counts: [u16; 3]) -> [f32; 3] {
        todo!()
    }
}
