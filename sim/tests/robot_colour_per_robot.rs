//! `[sensor] per_robot`: each robot reads the screen through its own fitted sensors from the file
//! `[rig] colour_calibration` names (the rig's sensors in the simulator). Two robots with very
//! different gains, crosstalk, dark counts and transfer curves read the same colour as the file's
//! models predict; `[randomize]` goes on top; a file that cannot serve the scenario is refused by key.
use colcos_sim::scenario::Scenario;
use colcos_sim::sensors::{ColourCalibration, RobotColour};
use colcos_sim::world::World;
use colcos_testkit::scenarios::glow_pair;
use colcos_testkit::sensors::{bright_crosstalk, dim_red};

/// Radio 1: a dim, red-leaning sensor; radio 2: a bright one with strong green-blue crosstalk.
fn calibration() -> ColourCalibration {
    ColourCalibration::new(
        "2026-11-24T00:00:00Z".into(),
        24.0,
        vec![
            RobotColour {
                radio_id: 1,
                sensors: [dim_red(); 4],
            },
            RobotColour {
                radio_id: 2,
                sensors: [bright_crosstalk(); 4],
            },
        ],
        6.0,
    )
}

/// Two robots near the centre of a screen that one wide, fixed Gaussian source paints an almost
/// uniform orange, reading it through `file`; no sensor noise. `per_robot`: each robot through its
/// own fitted sensors.
fn scenario(file: &str, per_robot: bool) -> Scenario {
    glow_pair(file)
        .with(|s| s.sensor.per_robot = per_robot)
        .build()
        .unwrap()
}

fn saved(cal: &ColourCalibration) -> (tempfile::TempDir, String) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("colour.json");
    cal.save(&path).unwrap();
    (dir, path.display().to_string())
}

#[test]
fn each_robot_reads_the_screen_through_its_own_fitted_model() {
    let cal = calibration();
    let (_dir, file) = saved(&cal);
    // The screen levels under every sensor, from the nominal sensor's exact inverse (no noise).
    let nominal = World::new(&scenario(&file, false)).unwrap();
    let own = World::new(&scenario(&file, true)).unwrap();
    let mut red = [0.0f64; 2];
    for (r, red) in red.iter_mut().enumerate() {
        let fitted = &cal.robots[r].sensors[0];
        for k in 0..4 {
            let levels = nominal.observations()[r].intensity[k].map(|v| v as f64 * 255.0);
            assert!(levels[0] > 100.0, "the screen is lit: {levels:?}");
            let want = fitted.predict(levels);
            let got = own.observations()[r].counts[k];
            for c in 0..3 {
                let tol = 2.0 + 0.005 * want[c];
                assert!(
                    (got[c] as f64 - want[c]).abs() < tol,
                    "robot {r} sensor {k} channel {c}: {got:?} against the file's {want:?}"
                );
            }
            // Its intensities come back through its own calibrated inverse: the screen's levels.
            let back = own.observations()[r].intensity[k];
            for c in 0..3 {
                assert!(
                    (back[c] as f64 * 255.0 - levels[c]).abs() < 1.5,
                    "robot {r}: {back:?} vs {levels:?}"
                );
            }
            *red = got[0] as f64;
        }
    }
    // The same orange, very different counts: the bright sensor counts well over twice the dim one.
    assert!(red[1] > 2.0 * red[0], "{red:?}");
}

#[test]
fn randomised_gain_goes_on_top_of_the_fitted_sensors() {
    let (_dir, file) = saved(&calibration());
    let plain = World::new(&scenario(&file, true)).unwrap();
    let doubled = glow_pair(&file)
        .with(|s| {
            s.sensor.per_robot = true;
            s.randomize.sensor_gain = Some([2.0, 2.0]);
        })
        .build()
        .unwrap();
    let doubled = World::new(&doubled).unwrap();
    let dark = calibration().robots[0].sensors[0].dark;
    let (a, b) = (
        plain.observations()[0].counts[1],
        doubled.observations()[0].counts[1],
    );
    for c in 0..3 {
        let (sa, sb) = (a[c] as f64 - dark[c], b[c] as f64 - dark[c]);
        assert!(
            (sb / sa - 2.0).abs() < 0.01,
            "channel {c}: {a:?} then {b:?}"
        );
    }
    // The calibrated inverse stays the file's: the doubled sensor reads the screen brighter.
    let (ia, ib) = (
        plain.observations()[0].intensity[1],
        doubled.observations()[0].intensity[1],
    );
    assert!(ib[0] > ia[0] + 0.05, "{ia:?} {ib:?}");
}

/// Why a world whose robots read through the calibration `file` is not built.
fn refusal(file: &str) -> String {
    World::new(&scenario(file, true))
        .err()
        .expect("refused")
        .to_string()
}

#[test]
fn a_file_that_cannot_serve_the_scenario_is_refused_by_key() {
    // One robot in the file, two in the scenario.
    let mut one = calibration();
    one.robots.truncate(1);
    let (_dir, file) = saved(&one);
    let err = refusal(&file);
    assert!(
        err.contains("rig.colour_calibration")
            && err.contains(&file)
            && err.contains("radio address 2"),
        "{err}"
    );

    // A singular matrix names the sensor in the file.
    let mut singular = calibration();
    singular.robots[1].sensors[2].matrix = [[1.0; 3]; 3];
    let (_dir2, file) = saved(&singular);
    let err = refusal(&file);
    assert!(
        err.contains("rig.colour_calibration") && err.contains("robots[1].sensors[2]"),
        "{err}"
    );

    // Not a calibration file at all.
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("screen.json");
    std::fs::write(&path, "{\"homography\": [1, 0, 0]}").unwrap();
    let file = path.display().to_string();
    let err = refusal(&file);
    assert!(
        err.contains("rig.colour_calibration") && err.contains("not a colour calibration file"),
        "{err}"
    );

    // A missing file, named.
    let err = refusal("/nonexistent/colour.json");
    assert!(err.contains("/nonexistent/colour.json"), "{err}");

    // The switch without a file is refused when the scenario is read.
    let text = "duration = 1.0\n[sensor]\nper_robot = true\n[[robots]]\ncount = 1\nbehaviour = \"wander\"\n";
    let err = Scenario::from_toml_str(text, ".")
        .expect_err("refused")
        .to_string();
    assert!(
        err.contains("sensor.per_robot") && err.contains("colour_calibration"),
        "{err}"
    );
}
