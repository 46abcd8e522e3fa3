//! Domain randomisation: every world draws its own values from the `[randomize]` ranges, the same for
//! the same seed and world index, inside the ranges; bad ranges are refused by key.
use colcos_sim::scenario::{RandomizeSpec, RobotGroupSpec, Scenario, ScenarioBuilder};
use colcos_sim::sensors::ColourSensorParams;
use colcos_sim::world::World;

/// Three robots wandering for 1 s on a 1 x 0.6 m screen, each world drawing from `randomize`.
fn scenario(randomize: RandomizeSpec) -> Scenario {
    ScenarioBuilder::new()
        .duration(1.0)
        .screen([384, 216], [1.0, 0.6])
        .robots(RobotGroupSpec::new(3, "wander"))
        .with(|s| s.randomize = randomize)
        .build()
        .unwrap()
}

#[test]
fn each_world_draws_its_own_values_within_the_ranges() {
    let sc = scenario(RandomizeSpec {
        tracker_latency: Some([0.03, 0.08]),
        position_noise: Some([0.0, 0.003]),
        sensor_gain: Some([0.8, 1.2]),
        crosstalk: Some([0.0, 0.05]),
        motor_lag: Some([0.02, 0.1]),
        max_wheel_speed: Some([0.2, 0.3]),
        ..RandomizeSpec::default()
    });
    let specs: Vec<_> = (0..32)
        .map(|w| World::with_index(&sc, w).unwrap().scenario().spec.clone())
        .collect();
    let latency: Vec<f32> = specs.iter().map(|s| s.tracker.latency).collect();
    assert!(
        latency.iter().all(|l| (0.03..=0.08).contains(l)),
        "{latency:?}"
    );
    let spread = latency.iter().cloned().fold(f32::MIN, f32::max)
        - latency.iter().cloned().fold(f32::MAX, f32::min);
    assert!(spread > 0.025, "32 draws spread over only {spread} s");
    for s in &specs {
        assert!(
            (0.8 * 1500.0..=1.2 * 1500.0).contains(&s.sensor.gain),
            "{}",
            s.sensor.gain
        );
        assert!((0.2..=0.3).contains(&s.robot.max_wheel_speed));
        assert!((0.02..=0.1).contains(&s.robot.motor_lag));
        let base = ColourSensorParams::default().crosstalk;
        let added = s.sensor.crosstalk[0][1] - base[0][1];
        assert!((-1e-6..=0.05 + 1e-6).contains(&added), "{added}");
        assert_eq!(s.sensor.crosstalk[0][0], base[0][0]);
    }
    // The same world index draws the same values again.
    let again = World::with_index(&sc, 5).unwrap();
    assert_eq!(again.scenario().spec.tracker.latency, latency[5]);
    // Without the section nothing is drawn.
    let plain = scenario(RandomizeSpec::default());
    let latency = World::with_index(&plain, 3)
        .unwrap()
        .scenario()
        .spec
        .tracker
        .latency;
    assert_eq!(latency, 0.04);
}

#[test]
fn bad_ranges_are_refused_by_key() {
    for (key, value, says) in [
        ("tracker_latency", "[0.08, 0.03]", "low <= high"),
        ("motor_lag", "[0.0, 5.0]", "within"),
        ("sensor_gain", "[0.0, 1.0]", "within"),
        ("crosstalk", "[nan, 0.1]", "finite"),
    ] {
        let text = format!(
            "duration = 1.0\n[[robots]]\ncount = 1\nbehaviour = \"wander\"\n[randomize]\n{key} = {value}\n"
        );
        let err = Scenario::from_toml_str(&text, ".").unwrap_err().to_string();
        assert!(
            err.contains(&format!("randomize.{key}")) && err.contains(says),
            "{err}"
        );
    }
}
