//! Colour calibration on the twin, whose robots' sensors each have their own crosstalk, gain, dark
//! counts and transfer curve: ramps shown through the frame stream, raw counts read over the radio
//! link, each sensor fitted; the fit reproduces counts at colours it never saw, and its inverse
//! gives the screen levels back.
mod calibrate_common;

use calibrate_common::{TwinRun, scenario, start_with};
use colcos_bridge::calibrate::run_colour::{ColourRunOptions, calibrate_colour};
use colcos_bridge::calibrate::{ColourCalibration, RigCalibration};
use colcos_sim::rng::{Stream, stream_of};
use colcos_sim::sensors::{ColourSensor, ColourSensorParams};

fn robot_params() -> Vec<ColourSensorParams> {
    let base = ColourSensorParams::default();
    vec![
        ColourSensorParams {
            gain: 1300.0,
            crosstalk: [[1.0, 0.12, 0.02], [0.05, 0.95, 0.14], [0.03, 0.10, 1.08]],
            dark_counts: 45.0,
            gamma: 2.35,
            ..base
        },
        ColourSensorParams {
            gain: 1700.0,
            crosstalk: [[0.92, 0.05, 0.06], [0.09, 1.05, 0.07], [0.01, 0.16, 0.97]],
            dark_counts: 20.0,
            gamma: 2.1,
            ..base
        },
        ColourSensorParams {
            gain: 1500.0,
            crosstalk: [[1.1, 0.02, 0.0], [0.02, 1.0, 0.2], [0.05, 0.05, 0.9]],
            dark_counts: 60.0,
            gamma: 2.2,
            ..base
        },
    ]
}

#[test]
fn per_robot_sensors_are_fitted_and_reproduce_held_out_counts() {
    let sc = scenario(&[(0.3, 0.3, 0.0), (0.7, 0.4, 45.0), (1.1, 0.5, 90.0)], "");
    let truth = robot_params();
    let t2 = truth.clone();
    let mut run: TwinRun = start_with(&sc, None, 0.0, 0.0, 40.0, move |twin| {
        for (i, p) in t2.into_iter().enumerate() {
            twin.plant_mut().set_sensor(i, p);
        }
    });
    let started = std::time::Instant::now();
    let cal = calibrate_colour(&mut run.rig, &sc, &ColourRunOptions::default()).unwrap();
    let took = started.elapsed().as_secs_f64();
    drop(run.stop());
    assert_eq!(cal.robots.len(), 3);

    // Fresh counts at colours the fit never saw, from each robot's true sensor (noise included).
    let mut rng = stream_of(21, 0, Stream::Telemetry(0));
    let (mut ss, mut n, mut worst) = (0.0, 0usize, 0.0f64);
    let mut worst_level = 0.0f64;
    let nominal = ColourSensor::new(sc.spec.sensor);
    for (r, params) in truth.iter().enumerate() {
        let sensor = ColourSensor::new(*params);
        let fit = &cal.robots[r];
        assert_eq!(fit.radio_id, r as u8 + 1);
        for s in &fit.sensors {
            let want = params.gain * params.integration_ms;
            let got = s.gain * cal.integration_ms * s.crosstalk[0][0];
            assert!(
                ((got - (want * params.crosstalk[0][0]) as f64) / got).abs() < 0.03,
                "robot {r}: {got} vs {want}"
            );
            assert!(
                (s.gamma - params.gamma as f64).abs() < 0.08,
                "robot {r}: {s:?}"
            );
        }
        for k in 0..40 {
            let levels = [
                (k * 53 % 256) as f32,
                (k * 97 % 256) as f32,
                (k * 31 % 256) as f32,
            ];
            let counts = sensor.counts(levels, &mut rng);
            let p = fit.sensors[1].predict(levels.map(|v| v as f64));
            for c in 0..3 {
                let e = p[c] - counts[c] as f64;
                ss += e * e;
                n += 1;
                worst = worst.max(e.abs());
            }
            // Through the calibrated inverse and the nominal model: the levels come back.
            let mut robot_counts = [[0u16; 3]; 4];
            robot_counts[1] = counts;
            let as_nominal = cal.to_nominal(r as u8 + 1, robot_counts, &nominal);
            let back = nominal.intensity(as_nominal[1]);
            for c in 0..3 {
                // Near black the transfer curve magnifies the sensor's own noise (8 counts are
                // ~6 levels at level 10): that is noise, not calibration.
                if levels[c] >= 40.0 {
                    worst_level = worst_level.max((back[c] * 255.0 - levels[c]).abs() as f64);
                }
            }
        }
    }
    let rms = (ss / n as f64).sqrt();
    eprintln!(
        "colour calibration on the twin (3 robots, sensor noise 8 counts): held-out counts {rms:.1} counts RMS (worst {worst:.0}; full scale ~42,000), in the run {:.1} counts RMS; fitted samples {:.1} counts RMS; levels of 40 and up back through the calibrated inverse within {worst_level:.1} of 255; took {took:.1} s",
        cal.held_out_rms_counts, cal.rms_counts
    );
    assert!(rms < 20.0, "{rms}");
    assert!(cal.held_out_rms_counts < 20.0, "{cal:?}");
    assert!(worst_level < 3.0, "{worst_level}");

    // The file round-trips and the scenario's [rig] key loads it.
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("colour.json");
    cal.save(&path).unwrap();
    let back = ColourCalibration::load(&path).unwrap();
    assert_eq!(back.robots.len(), 3);
    let rig_text = format!("colour_calibration = \"{}\"", path.display());
    let loaded = RigCalibration::load(&scenario(&[(0.3, 0.3, 0.0)], &rig_text)).unwrap();
    assert!(loaded.colour.is_some() && loaded.screen.is_none());

    // A file with a singular matrix is refused, naming the sensor.
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
    let sc = scenario(
        &[(0.3, 0.3, 0.0)],
        "colour_calibration = \"/nonexistent/colour.json\"",
    );
    let err = colcos_bridge::live::LoopCore::new(&sc, Default::default())
        .err()
        .expect("refused")
        .to_string();
    assert!(err.contains("/nonexistent/colour.json"), "{err}");
}
