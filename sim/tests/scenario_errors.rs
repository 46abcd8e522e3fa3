//! Every kind of bad scenario input is refused before anything runs, with the key path and the value.
use colcos_sim::error::SimError;
use colcos_sim::scenario::Scenario;
use colcos_testkit::parsing::{TRAIL_AVOIDERS, assert_all_refused, assert_refused, refusal_in};
use std::path::Path;

/// Three robots that avoid each other laying a `trail`.
fn good() -> String {
    format!(
        "{TRAIL_AVOIDERS}deposits = [{{ pheromone = \"trail\", kernel = {{ shape = \"disc\", radius = 0.01 }}, rate = 1.0 }}]\n"
    )
}

/// [`good`] with `from` replaced by `to`.
fn with(from: &str, to: &str) -> String {
    good().replace(from, to)
}

/// [`good`] and `table` after it.
fn plus(table: &str) -> String {
    format!("{}\n{table}\n", good())
}

fn err(text: &str) -> String {
    refusal_in(text, Path::new("."))
}

#[test]
fn the_good_one_parses() {
    let sc = Scenario::from_toml_str(&good(), ".").unwrap();
    assert_eq!(sc.robot_count(), 3);
    assert_eq!(sc.steps(), 50);
}

#[test]
fn unknown_keys_are_rejected_with_their_path() {
    assert_all_refused(&[
        (
            with("duration = 1.0", "duration = 1.0\nspeed = 3"),
            &["speed"],
        ),
        (
            with("evaporation = 10.0", "evaporation = 10.0\ndiffusivity = 1"),
            &["pheromones[0]", "diffusivity"],
        ),
        (
            with("count = 3", "count = 3\ncolor = 1"),
            &["robots[0]", "color"],
        ),
        (plus("[tracker]\nrate = 30"), &["tracker", "rate"]),
    ]);
}

#[test]
fn wrong_types_name_the_key() {
    assert_all_refused(&[
        (with("count = 3", "count = \"three\""), &["robots[0].count"]),
        (with("duration = 1.0", "duration = \"long\""), &["duration"]),
    ]);
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
    assert_all_refused(&[
        (
            with("evaporation = 10.0", "evaporation = -5.0"),
            &["pheromones[0].evaporation", "-5"],
        ),
        (with("duration = 1.0", "duration = 0.0"), &["duration", "0"]),
        (
            with("duration = 1.0", "duration = 1.0\ndt = -0.02"),
            &["dt", "-0.02"],
        ),
        (plus("[robot]\nradius = 0.0"), &["robot.radius"]),
        (
            plus("[robot]\nradius = 1.0"),
            &["robot.radius", "does not fit"],
        ),
        (
            plus("[tracker]\ndropout = 1.5"),
            &["tracker.dropout", "1.5"],
        ),
        (plus("[field]\ncell = 0"), &["field.cell"]),
        (
            plus("[sensor]\ncrosstalk = [[1,1,1],[1,1,1],[1,1,1]]"),
            &["sensor.crosstalk", "singular"],
        ),
    ]);
}

#[test]
fn too_many_robots_do_not_fit() {
    assert_all_refused(&[
        (
            with("count = 3", "count = 100000"),
            &["robots[0].count", "100000"],
        ),
        (
            with("count = 3", "count = 3\nregion = [0.0, 0.0, 0.05, 0.05]"),
            &["robots[0].count", "fit"],
        ),
        (
            with("count = 3", "count = 3\nregion = [0.0, 0.0, 5.0, 0.5]"),
            &["robots[0].region"],
        ),
    ]);
}

#[test]
fn references_must_exist() {
    assert_all_refused(&[
        (
            with("pheromone = \"trail\"", "pheromone = \"trial\""),
            &["robots[0].deposits[0].pheromone", "trial", "trail"],
        ),
        (
            with("behaviour = \"avoid\"", "behaviour = \"dance\""),
            &["robots[0].behaviour", "dance", "wander"],
        ),
        (
            with(
                "behaviour = \"avoid\"",
                "behaviour = \"avoid\"\nparams = { speeed = 1 }",
            ),
            &["robots[0].params", "speeed"],
        ),
        (
            with(
                "behaviour = \"avoid\"",
                "behaviour = \"avoid\"\nparams = { speed = -1 }",
            ),
            &["robots[0].params.speed", "-1"],
        ),
    ]);
}

#[test]
fn explicit_placement_needs_poses_inside() {
    assert_all_refused(&[
        (
            with(
                "count = 3",
                "count = 2\nplacement = \"explicit\"\nposes = [[0.5, 0.5, 0.0]]",
            ),
            &["robots[0].poses", "1"],
        ),
        (
            with(
                "count = 3",
                "count = 1\nplacement = \"explicit\"\nposes = [[5.0, 0.5, 0.0]]",
            ),
            &["robots[0].poses[0]", "not inside"],
        ),
    ]);
}

/// [`good`] with the trail's `maps` (a TOML array's items).
fn with_maps(maps: &str) -> String {
    with(
        "evaporation = 10.0",
        &format!("evaporation = 10.0\nmaps = [{maps}]"),
    )
}

#[test]
fn maps_and_sources_are_checked() {
    let gauss = "evaporation = 10.0\nmodel = \"gaussian\"\nsources = [{ k = 1, sigma = [0.1, 0.1], rho = 1.0, evaporation = 5 }]";
    assert_all_refused(&[
        (
            with_maps("{ polyline = [[0.1, 0.1]], width = 0.01, rate = 1 }"),
            &["pheromones[0].maps[0].polyline"],
        ),
        (
            with_maps("{ polyline = [[0.1, 0.1], [0.2, 0.2]], rate = 1 }"),
            &["pheromones[0].maps[0].width", "missing"],
        ),
        (
            with("evaporation = 10.0", gauss),
            &["pheromones[0].sources[0].rho"],
        ),
    ]);
}

#[test]
fn missing_image_is_a_clear_error_at_validation() {
    let text = with_maps("{ image = \"no_such_file.png\", rate = 1 }");
    // Refused before any world is built, with the key path and the file name.
    let e = err(&text);
    assert!(e.contains("pheromones[0].maps[0].image"), "{e}");
    assert!(e.contains("no_such_file.png"), "{e}");
}

/// A map is a polyline (with a width) or an image (with a channel): keys of the other kind, both
/// kinds or neither are refused as the file is read, naming the key.
#[test]
fn a_map_has_the_keys_of_one_kind() {
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
        assert_refused(&with_maps(&map), &[key, why]);
    }
}

#[test]
fn rig_compensation_needs_a_file_and_no_second_correction() {
    assert_all_refused(&[
        (
            plus("[rig]\ncompensate = \"\""),
            &["rig.compensate", "must name a file"],
        ),
        (
            plus("[rig]\ncompensate = \"fit.toml\"\ncolour_calibration = \"colour.toml\""),
            &[
                "rig.compensate",
                "fit.toml",
                "rig.colour_calibration",
                "name one of the two",
            ],
        ),
        (
            plus("[rig]\ncompensate = \"fit.toml\"\nonboard = \"policy.json\""),
            &["rig.compensate", "drives the wheels itself"],
        ),
    ]);
}
