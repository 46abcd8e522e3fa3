//! Colour calibration on the twin, whose robots' sensors come from a colour calibration file
//! (`[sensor] per_robot = true`, `[rig] colour_calibration`): each of the twin's robots reports its
//! own sensors' counts in telemetry; `colcos calibrate colour` on that twin (ramps shown through the
//! frame stream, raw counts read over the radio link) gives the file's models back, reproduces counts
//! at colours it never saw, and its inverse gives the screen levels back.
use colcos_bridge::calibrate::RigCalibration;
use colcos_bridge::calibrate::{ColourRunOptions, calibrate_colour};
use colcos_bridge::twin::TwinArena;
use colcos_sim::rng::{Stream, stream_of};
use colcos_sim::scenario::{Scenario, ScenarioBuilder};
use colcos_sim::sensors::{ColourCalibration, ColourSensor, RobotColour};
use colcos_testkit::scenarios::parked;
use colcos_testkit::sensors::{bright_crosstalk, dim_red, fit};
use colcos_testkit::twin::TwinRun;
use image::RgbImage;

/// Three robots: a dim red-leaning one; a bright one with strong green-blue crosstalk whose front
/// sensor differs from its other three; a third with a high dark level.
fn file_models() -> ColourCalibration {
    let (a, b) = (dim_red(), bright_crosstalk());
    let b_front = fit(
        2.1,
        1800.0,
        [[1.0, 0.05, 0.1], [0.2, 0.9, 0.1], [0.0, 0.1, 1.0]],
        [40.0, 40.0, 15.0],
    );
    let c = fit(
        2.2,
        1500.0,
        [[1.1, 0.02, 0.0], [0.02, 1.0, 0.2], [0.05, 0.05, 0.9]],
        [60.0, 60.0, 60.0],
    );
    let robot = |radio_id, sensors| RobotColour { radio_id, sensors };
    ColourCalibration::new(
        "2026-11-24T00:00:00Z".into(),
        24.0,
        vec![
            robot(1, [a; 4]),
            robot(2, [b, b_front, b, b]),
            robot(3, [c; 4]),
        ],
        6.0,
    )
}

/// Robots parked at `poses` on the panel whose rig's colour calibration is the file `path`.
fn reading_through(poses: &[[f32; 3]], path: &str) -> ScenarioBuilder {
    parked(poses).with(|s| s.rig.colour_calibration = Some(path.to_string()))
}

/// The twin of three robots reading through `file` (saved in `dir`).
fn twin_scenario(file: &ColourCalibration, dir: &std::path::Path) -> Scenario {
    let path = dir.join("colour.json");
    file.save(&path).unwrap();
    let robots = [[0.3, 0.3, 0.0], [0.7, 0.4, 45.0], [1.1, 0.5, 90.0]];
    reading_through(&robots, &path.display().to_string())
        .with(|s| s.sensor.per_robot = true)
        .build()
        .unwrap()
}

/// What the twin's robots report for one uniform colour: each sensor's own model, within noise.
#[test]
fn the_twins_robots_read_through_their_own_sensors() {
    let file = file_models();
    let dir = tempfile::tempdir().unwrap();
    let mut arena = TwinArena::new(&twin_scenario(&file, dir.path())).unwrap();
    let levels = [180.0, 90.0, 40.0];
    let frame = RgbImage::from_pixel(384, 216, image::Rgb(levels.map(|v| v as u8)));
    for (r, robot) in file.robots.iter().enumerate() {
        let mut mean = [[0.0f64; 3]; 4];
        for _ in 0..16 {
            let counts = arena.colour_counts(r, Some(&frame));
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
}

#[test]
fn calibrating_the_twin_gives_the_file_back_and_predicts_unseen_colours() {
    let file = file_models();
    let dir = tempfile::tempdir().unwrap();
    let sc = twin_scenario(&file, dir.path());
    let mut run = TwinRun::start(&sc, None, 0.0, 0.0, 40.0);
    let started = std::time::Instant::now();
    let cal = calibrate_colour(&mut run.rig, &sc, &ColourRunOptions::default()).unwrap();
    let took = started.elapsed().as_secs_f64();
    drop(run.stop());
    assert_eq!(cal.robots.len(), 3);

    // The models come back.
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

    // Fresh counts at colours the fit never saw, from each robot's true front sensor (noise
    // included), and the levels back through the calibrated inverse and the nominal model.
    let mut rng = stream_of(21, 0, Stream::Telemetry(0));
    let (mut ss, mut n, mut worst) = (0.0, 0usize, 0.0f64);
    let mut worst_level = 0.0f64;
    let nominal = ColourSensor::new(sc.spec.sensor);
    for (r, robot) in file.robots.iter().enumerate() {
        let truth = robot.sensors[1].sensor(&sc.spec.sensor, 1.0, &[[0.0; 3]; 3]);
        let fitted = &cal.robots[r].sensors[1];
        for k in 0..40 {
            let levels = [
                (k * 53 % 256) as f32,
                (k * 97 % 256) as f32,
                (k * 31 % 256) as f32,
            ];
            let counts = truth.counts(levels, &mut rng);
            let p = fitted.predict(levels.map(|v| v as f64));
            for c in 0..3 {
                let e = p[c] - counts[c] as f64;
                ss += e * e;
                n += 1;
                worst = worst.max(e.abs());
            }
            let mut robot_counts = [[0u16; 3]; 4];
            robot_counts[1] = counts;
            let as_nominal = cal.to_nominal(r as u8 + 1, robot_counts, &nominal);
            let back = nominal.intensity(as_nominal[1]);
            for c in 0..3 {
                // Near black the transfer curve magnifies the sensor's own noise (8 counts are
                // ~6 levels at level 10), and a saturated channel says nothing: not calibration.
                if levels[c] >= 40.0 && counts[c] < 65_535 {
                    worst_level = worst_level.max((back[c] * 255.0 - levels[c]).abs() as f64);
                }
            }
        }
    }
    let rms = (ss / n as f64).sqrt();
    eprintln!(
        "colour file -> twin -> calibrate colour (3 robots, sensor noise 8 counts): gamma within {worst_gamma:.3}, matrix within {:.2} % of the sensor's largest entry, dark within {worst_dark:.1} counts; held-out counts {rms:.1} counts RMS (worst {worst:.0}), in the run {:.1}; fitted samples {:.1} counts RMS; levels of 40 and up back through the calibrated inverse within {worst_level:.1} of 255; took {took:.1} s",
        100.0 * worst_matrix,
        cal.held_out_rms_counts,
        cal.rms_counts
    );
    assert!(worst_gamma < 0.08, "{cal:?}");
    assert!(worst_matrix < 0.03, "{cal:?}");
    assert!(worst_dark < 15.0, "{cal:?}");
    assert!(rms < 20.0, "{rms}");
    assert!(cal.held_out_rms_counts < 20.0, "{cal:?}");
    assert!(worst_level < 3.0, "{worst_level}");
}

/// The file round-trips, the scenario's `[rig]` key loads it, and a singular matrix is refused
/// naming the sensor.
#[test]
fn calibration_files_load_and_bad_ones_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("colour.json");
    file_models().save(&path).unwrap();
    let back = ColourCalibration::load(&path).unwrap();
    assert_eq!(back.robots.len(), 3);
    let sc = reading_through(&[[0.3, 0.3, 0.0]], &path.display().to_string())
        .build()
        .unwrap();
    let loaded = RigCalibration::load(&sc).unwrap();
    assert!(loaded.colour.is_some() && loaded.screen.is_none());
    let text = std::fs::read_to_string(&path).unwrap();
    let mut json: serde_json::Value = serde_json::from_str(&text).unwrap();
    json["robots"][1]["sensors"][2]["matrix"] =
        serde_json::json!([[1, 1, 1], [1, 1, 1], [1, 1, 1]]);
    std::fs::write(&path, json.to_string()).unwrap();
    let err = ColourCalibration::load(&path).unwrap_err().to_string();
    assert!(err.contains("robots[1].sensors[2]"), "{err}");
}

/// The live loop loads the scenario's calibrations: a file that is not there stops it before it
/// starts, naming the file.
#[test]
fn the_live_loop_refuses_a_missing_calibration_file() {
    let sc = reading_through(&[[0.3, 0.3, 0.0]], "/nonexistent/colour.json")
        .build()
        .unwrap();
    let err = colcos_bridge::rig::LoopCore::new(&sc, Default::default())
        .err()
        .expect("refused")
        .to_string();
    assert!(err.contains("/nonexistent/colour.json"), "{err}");
}
