//! Fit on the rig, train on it: a twin whose robots' sensors come from a colour calibration file
//! (`[sensor] per_robot = true`, `[rig] colour_calibration`) serves each robot's own counts in its
//! telemetry, and `colcos calibrate colour` on that twin gives the file's models back.
mod calibrate_common;

use calibrate_common::{TwinRun, scenario};
use colcos_bridge::calibrate::run_colour::{ColourRunOptions, calibrate_colour};
use colcos_bridge::twin::TwinPlant;
use colcos_sim::sensors::{ColourCalibration, RobotColour, SensorFit};
use image::RgbImage;

fn fit(gamma: f64, gain: f64, crosstalk: [[f64; 3]; 3], dark: [f64; 3]) -> SensorFit {
    SensorFit::from_parts(gamma, gain, crosstalk, dark, 24.0)
}

/// Two robots far apart: a dim red-leaning one and a bright one with strong green-blue crosstalk
/// whose front sensor differs from its other three.
fn file_models() -> ColourCalibration {
    let a = fit(
        2.4,
        900.0,
        [[1.2, 0.02, 0.0], [0.03, 0.8, 0.05], [0.01, 0.04, 0.7]],
        [20.0, 35.0, 50.0],
    );
    let b = fit(
        1.9,
        2100.0,
        [[0.9, 0.15, 0.05], [0.1, 1.05, 0.3], [0.05, 0.35, 1.1]],
        [60.0, 10.0, 25.0],
    );
    let b_front = fit(
        2.1,
        1800.0,
        [[1.0, 0.05, 0.1], [0.2, 0.9, 0.1], [0.0, 0.1, 1.0]],
        [40.0, 40.0, 15.0],
    );
    ColourCalibration::new(
        "2026-11-24T00:00:00Z".into(),
        24.0,
        vec![
            RobotColour {
                radio_id: 1,
                sensors: [a; 4],
            },
            RobotColour {
                radio_id: 2,
                sensors: [b, b_front, b, b],
            },
        ],
        6.0,
    )
}

#[test]
fn calibrating_a_twin_built_from_a_file_gives_the_file_back() {
    let file = file_models();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("colour.json");
    file.save(&path).unwrap();
    let rig = format!(
        "colour_calibration = \"{}\"\n[sensor]\nper_robot = true",
        path.display()
    );
    let sc = scenario(&[(0.4, 0.3, 0.0), (1.0, 0.5, 90.0)], &rig);

    // What the twin's robots report for one uniform colour: each sensor's own model, within noise.
    let mut plant = TwinPlant::new(&sc).unwrap();
    let levels = [180.0, 90.0, 40.0];
    let frame = RgbImage::from_pixel(384, 216, image::Rgb(levels.map(|v| v as u8)));
    for (r, robot) in file.robots.iter().enumerate() {
        let mut mean = [[0.0f64; 3]; 4];
        for _ in 0..16 {
            let counts = plant.colour_counts(r, Some(&frame));
            for k in 0..4 {
                for c in 0..3 {
                    mean[k][c] += counts[k][c] as f64 / 16.0;
                }
            }
        }
        for (k, (mean, sensor)) in mean.iter().zip(&robot.sensors).enumerate() {
            let want = sensor.predict(levels);
            for c in 0..3 {
                // Noise of 8 counts over 16 readings: 2 counts; rounding of the model in f32.
                assert!(
                    (mean[c] - want[c]).abs() < 8.0 + 0.002 * want[c],
                    "robot {r} sensor {k}: {mean:?} against the file's {want:?}"
                );
            }
        }
    }

    // The calibration over the wires gives the file's models back.
    let mut run = TwinRun::start(&sc, None, 0.0, 0.0, 40.0);
    let cal = calibrate_colour(&mut run.rig, &sc, &ColourRunOptions::default()).unwrap();
    drop(run.stop());
    let (mut worst_gamma, mut worst_matrix, mut worst_dark) = (0.0f64, 0.0f64, 0.0f64);
    for (want, got) in file.robots.iter().zip(&cal.robots) {
        assert_eq!(want.radio_id, got.radio_id);
        for (w, g) in want.sensors.iter().zip(&got.sensors) {
            worst_gamma = worst_gamma.max((w.gamma - g.gamma).abs());
            let scale = (0..3).map(|c| w.matrix[c][c]).fold(0.0, f64::max);
            for c in 0..3 {
                worst_dark = worst_dark.max((w.dark[c] - g.dark[c]).abs());
                for k in 0..3 {
                    worst_matrix =
                        worst_matrix.max((w.matrix[c][k] - g.matrix[c][k]).abs() / scale);
                }
            }
        }
    }
    eprintln!(
        "colour file -> twin -> calibrate colour: gamma within {worst_gamma:.3}, matrix within {:.2} % of the sensor's largest entry, dark within {worst_dark:.1} counts (sensor noise 8 counts)",
        100.0 * worst_matrix
    );
    assert!(worst_gamma < 0.08, "{cal:?}");
    assert!(worst_matrix < 0.03, "{cal:?}");
    assert!(worst_dark < 15.0, "{cal:?}");
}
