//! Every kind of bad scenario input is refused before anything runs, with the key path and the value.
use colcos_sim::error::SimError;
use colcos_sim::scenario::Scenario;

const GOOD: &str = r#"
duration = 1.0
[[pheromones]]
name = "trail"
colour = [0, 0, 255]
evaporation = 10.0
[[robots]]
count = 3
behaviour = "avoid"
deposits = [{ pheromone = "trail", kernel = { shape = "disc", radius = 0.01 }, rate = 1.0 }]
"#;

fn err(text: &str) -> String {
    match Scenario::from_toml_str(text, ".") {
        Ok(_) => panic!("scenario was accepted:\n{text}"),
        Err(e) => e.to_string(),
    }
}

fn assert_err(text: &str, needles: &[&str]) {
    let msg = err(text);
    for n in needles {
        assert!(msg.contains(n), "error {msg:?} does not mention {n:?}");
    }
}

#[test]
fn the_good_one_parses() {
    let sc = Scenario::from_toml_str(GOOD, ".").unwrap();
    assert_eq!(sc.robot_count(), 3);
    assert_eq!(sc.steps(), 50);
}

#[test]
fn unknown_keys_are_rejected_with_their_path() {
    assert_err(
        &GOOD.replace("duration = 1.0", "duration = 1.0\nspeed = 3"),
        &["speed"],
    );
    assert_err(
        &GOOD.replace("evaporation = 10.0", "evaporation = 10.0\ndiffusivity = 1"),
        &["pheromones[0]", "diffusivity"],
    );
    assert_err(
        &GOOD.replace("count = 3", "count = 3\ncolor = 1"),
        &["robots[0]", "color"],
    );
    assert_err(
        &format!("{GOOD}\n[tracker]\nrate = 30\n"),
        &["tracker", "rate"],
    );
}

#[test]
fn wrong_types_name_the_key() {
    assert_err(
        &GOOD.replace("count = 3", "count = \"three\""),
        &["robots[0].count"],
    );
    assert_err(
        &GOOD.replace("duration = 1.0", "duration = \"long\""),
        &["duration"],
    );
}

#[test]
fn malformed_toml_is_a_parse_error() {
    assert!(matches!(
        Scenario::from_toml_str("duration = = 1", "."),
        Err(SimError::Parse { .. })
    ));
}

#[test]
fn impossible_physics_is_refused() {
    assert_err(
        &GOOD.replace("evaporation = 10.0", "evaporation = -5.0"),
        &["pheromones[0].evaporation", "-5"],
    );
    assert_err(
        &GOOD.replace("duration = 1.0", "duration = 0.0"),
        &["duration", "0"],
    );
    assert_err(
        &GOOD.replace("duration = 1.0", "duration = 1.0\ndt = -0.02"),
        &["dt", "-0.02"],
    );
    assert_err(
        &format!("{GOOD}\n[robot]\nradius = 0.0\n"),
        &["robot.radius"],
    );
    assert_err(
        &format!("{GOOD}\n[robot]\nradius = 1.0\n"),
        &["robot.radius", "does not fit"],
    );
    assert_err(
        &format!("{GOOD}\n[tracker]\ndropout = 1.5\n"),
        &["tracker.dropout", "1.5"],
    );
    assert_err(&format!("{GOOD}\n[field]\ncell = 0\n"), &["field.cell"]);
    assert_err(
        &format!("{GOOD}\n[sensor]\ncrosstalk = [[1,1,1],[1,1,1],[1,1,1]]\n"),
        &["sensor.crosstalk", "singular"],
    );
}

#[test]
fn too_many_robots_do_not_fit() {
    assert_err(
        &GOOD.replace("count = 3", "count = 100000"),
        &["robots[0].count", "100000"],
    );
    assert_err(
        &GOOD.replace("count = 3", "count = 3\nregion = [0.0, 0.0, 0.05, 0.05]"),
        &["robots[0].count", "fit"],
    );
    assert_err(
        &GOOD.replace("count = 3", "count = 3\nregion = [0.0, 0.0, 5.0, 0.5]"),
        &["robots[0].region"],
    );
}

#[test]
fn references_must_exist() {
    assert_err(
        &GOOD.replace("pheromone = \"trail\"", "pheromone = \"trial\""),
        &["robots[0].deposits[0].pheromone", "trial", "trail"],
    );
    assert_err(
        &GOOD.replace("behaviour = \"avoid\"", "behaviour = \"dance\""),
        &["robots[0].behaviour", "dance", "wander"],
    );
    assert_err(
        &GOOD.replace(
            "behaviour = \"avoid\"",
            "behaviour = \"avoid\"\nparams = { speeed = 1 }",
        ),
        &["robots[0].params", "speeed"],
    );
    assert_err(
        &GOOD.replace(
            "behaviour = \"avoid\"",
            "behaviour = \"avoid\"\nparams = { speed = -1 }",
        ),
        &["robots[0].params.speed", "-1"],
    );
}

#[test]
fn explicit_placement_needs_poses_inside() {
    let text = GOOD.replace(
        "count = 3",
        "count = 2\nplacement = \"explicit\"\nposes = [[0.5, 0.5, 0.0]]",
    );
    assert_err(&text, &["robots[0].poses", "1"]);
    let text = GOOD.replace(
        "count = 3",
        "count = 1\nplacement = \"explicit\"\nposes = [[5.0, 0.5, 0.0]]",
    );
    assert_err(&text, &["robots[0].poses[0]", "not inside"]);
}

#[test]
fn maps_and_sources_are_checked() {
    let map = GOOD.replace(
        "evaporation = 10.0",
        "evaporation = 10.0\nmaps = [{ polyline = [[0.1, 0.1]], width = 0.01, rate = 1 }]",
    );
    assert_err(&map, &["pheromones[0].maps[0].polyline"]);
    let map = GOOD.replace(
        "evaporation = 10.0",
        "evaporation = 10.0\nmaps = [{ polyline = [[0.1, 0.1], [0.2, 0.2]], rate = 1 }]",
    );
    assert_err(&map, &["pheromones[0].maps[0].width", "missing"]);
    let gauss = GOOD.replace("evaporation = 10.0", "evaporation = 10.0\nmodel = \"gaussian\"\nsources = [{ k = 1, sigma = [0.1, 0.1], rho = 1.0, evaporation = 5 }]");
    assert_err(&gauss, &["pheromones[0].sources[0].rho"]);
}

#[test]
fn missing_image_is_a_clear_error_at_validation() {
    let text = GOOD.replace(
        "evaporation = 10.0",
        "evaporation = 10.0\nmaps = [{ image = \"no_such_file.png\", rate = 1 }]",
    );
    // Refused before any world is built, with the key path and the file name.
    let e = err(&text);
    assert!(e.contains("pheromones[0].maps[0].image"), "{e}");
    assert!(e.contains("no_such_file.png"), "{e}");
}

/// A map is a polyline (with a width) or an image (with a channel): keys of the other kind, both
/// kinds or neither are refused as the file is read, naming the key.
#[test]
fn a_map_has_the_keys_of_one_kind() {
    let with = |m: &str| {
        GOOD.replace(
            "evaporation = 10.0",
            &format!("evaporation = 10.0\nmaps = [{m}]"),
        )
    };
    let line = "polyline = [[0.1, 0.1], [0.2, 0.2]]";
    let cases = [
        (
            format!("{{ {line}, width = 0.01, channel = \"r\", rate = 1 }}"),
            "pheromones[0].maps[0].channel",
            "only image maps",
        ),
        (
            "{ image = \"m.png\", width = 0.01, rate = 1 }".to_string(),
            "pheromones[0].maps[0].width",
            "only polyline maps",
        ),
        (
            "{ image = \"m.png\", channel = \"a\", rate = 1 }".to_string(),
            "pheromones[0].maps[0].channel",
            "\"luma\"",
        ),
        (
            format!("{{ {line}, image = \"m.png\", width = 0.01, rate = 1 }}"),
            "pheromones[0].maps[0]",
            "exactly one of",
        ),
        (
            "{ rate = 1 }".to_string(),
            "pheromones[0].maps[0]",
            "exactly one of",
        ),
        (
            format!("{{ {line}, width = 0.01, rate = 1, colour = 3 }}"),
            "pheromones[0].maps[0]",
            "colour",
        ),
    ];
    for (map, key, why) in cases {
        assert_err(&with(&map), &[key, why]);
    }
}
