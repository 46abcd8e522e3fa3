//! Fitted colour sensors with very different characters, for the tests of per-robot sensing and of
//! colour calibration: models a calibration file holds, to be read back or recovered.
use colcos_sim::sensors::SensorFit;

/// A fitted sensor at 24 ms integration: transfer curve `gamma`, `gain` counts per unit light per
/// ms, `crosstalk` between channels and `dark` counts per channel.
pub fn fit(gamma: f64, gain: f64, crosstalk: [[f64; 3]; 3], dark: [f64; 3]) -> SensorFit {
    SensorFit::from_parts(gamma, gain, crosstalk, dark, 24.0)
}

/// Channel mixing of a red-leaning sensor: red read strongly, the others weakly, little leaking.
const RED_LEANING: [[f64; 3]; 3] = [[1.2, 0.02, 0.0], [0.03, 0.8, 0.05], [0.01, 0.04, 0.7]];
/// Channel mixing with green and blue leaking strongly into each other.
const GREEN_BLUE_LEAKING: [[f64; 3]; 3] = [[0.9, 0.15, 0.05], [0.1, 1.05, 0.3], [0.05, 0.35, 1.1]];

/// A dim, red-leaning sensor.
pub fn dim_red() -> SensorFit {
    fit(2.4, 900.0, RED_LEANING, [20.0, 35.0, 50.0])
}

/// A bright sensor with strong green-blue crosstalk.
pub fn bright_crosstalk() -> SensorFit {
    fit(1.9, 2100.0, GREEN_BLUE_LEAKING, [60.0, 10.0, 25.0])
}
