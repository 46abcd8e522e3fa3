//! What validation refuses beyond single values: whatever the world build would refuse (images,
//! placement), work and memory beyond stated limits, and input that parsed but means nothing.
use colcos_sim::scenario::{Scenario, parse_spec};
use colcos_sim::world::World;
use colcos_testkit::parsing::{
    TRAIL_AVOIDERS as GOOD, assert_all_refused, assert_refused, assert_refused_in,
};
use std::path::Path;

fn check(text: &str, dir: &Path) -> Result<Scenario, String> {
    Scenario::from_toml_str(text, dir).map_err(|e| e.to_string())
}

/// [`GOOD`] and `table` after it.
fn plus(table: &str) -> String {
    format!("{GOOD}\n{table}\n")
}

fn with_map(map: &str) -> String {
    GOOD.replace(
        "evaporation = 10.0",
        &format!("evaporation = 10.0\nmaps = [{map}]"),
    )
}

fn with_robots(robots: &str) -> String {
    GOOD.replace("count = 3\nbehaviour = \"avoid\"", robots)
}

// Class 1: a scenario that validates also builds.

#[test]
fn image_maps_are_opened_by_validation() {
    let dir = tempfile::tempdir().unwrap();
    let image = |name: &str| with_map(&format!("{{ image = \"{name}\", rate = 1 }}"));
    let key = "pheromones[0].maps[0].image";
    assert_refused_in(&image("missing.png"), dir.path(), &[key, "missing.png"]);
    std::fs::create_dir(dir.path().join("folder.png")).unwrap();
    assert_refused_in(&image("folder.png"), dir.path(), &[key, "not a file"]);
    std::fs::write(dir.path().join("text.png"), "not an image").unwrap();
    assert_refused_in(&image("text.png"), dir.path(), &[key, "PNG signature"]);
    image::RgbImage::new(4, 3)
        .save(dir.path().join("map.png"))
        .unwrap();
    let sc = check(&image("map.png"), dir.path()).expect("a real PNG");
    World::new(&sc).expect("and it builds");
}

#[test]
fn placement_that_cannot_succeed_is_refused_with_the_key() {
    // 25 robots fit a square packing of the 0.2 m region, but not random placement with gaps.
    assert_refused(
        &with_robots("count = 25\nbehaviour = \"avoid\"\nregion = [0.5, 0.5, 0.7, 0.7]"),
        &["robots[0].placement", "crowded"],
    );
    // Against the walls the grid shrinks below a diameter.
    assert_refused(
        &with_robots(
            "count = 25\nbehaviour = \"avoid\"\nplacement = \"grid\"\nregion = [0.0, 0.0, 0.2, 0.2]",
        ),
        &["robots[0].placement", "grid"],
    );
    // No room clear of the walls: the world build used to panic on an empty range here.
    let narrow = format!(
        "{}\n[arena]\nsize = [0.041, 1.0]\n",
        with_robots("count = 1\nbehaviour = \"avoid\"")
    );
    assert_refused(&narrow, &["robots[0].placement", "no room"]);
}

/// The validation's placement is the world's: for seeds and crowding around the edge of what fits,
/// validation accepts exactly the scenarios whose world builds.
#[test]
fn validation_places_as_the_world_does() {
    let (mut accepted, mut refused) = (0, 0);
    for count in [14, 16, 18, 20, 22] {
        for seed in 0..4 {
            let text = format!(
                "seed = {seed}\n{}",
                with_robots(&format!(
                    "count = {count}\nbehaviour = \"avoid\"\nregion = [0.5, 0.5, 0.7, 0.7]"
                ))
            );
            let spec = parse_spec(&text).unwrap();
            let unchecked = Scenario {
                spec: spec.clone(),
                base_dir: ".".into(),
            };
            let builds = World::new(&unchecked).is_ok();
            let validates = Scenario::from_spec(spec, ".").is_ok();
            assert_eq!(builds, validates, "count {count}, seed {seed}");
            if validates {
                accepted += 1;
            } else {
                refused += 1;
            }
        }
    }
    assert!(
        accepted > 0 && refused > 0,
        "{accepted} accepted, {refused} refused"
    );
}

// Class 2: work and memory per step are bounded, each limit named.

#[test]
fn work_and_memory_are_bounded() {
    let grid = |extra: &str| {
        GOOD.replace(
            "evaporation = 10.0",
            &format!("evaporation = 10.0\n{extra}"),
        )
    };
    for accepted in [
        grid("diffusion = 1.0\nscheme = \"implicit\""),
        grid("wind = [0.1, 0.0]"),
        // No GIF, no frame size.
        plus("[output]\ngif_width = 100000\ngif_interval = 0.0"),
    ] {
        check(&accepted, Path::new(".")).expect(&accepted);
    }
    assert_all_refused(&[
        // r = d dt / h^2 = 1 * 0.02 / 0.005^2 = 800: 3200 explicit sub-steps.
        (
            grid("diffusion = 1.0\nscheme = \"explicit\""),
            &["pheromones[0].diffusion", "explicit", "sub-steps", "1000"],
        ),
        (
            grid("diffusion = 1.0\nscheme = \"one_sided\""),
            &["pheromones[0].diffusion", "1000"],
        ),
        (
            grid("wind = [1000.0, 0.0]"),
            &["pheromones[0].wind", "1000"],
        ),
        (
            plus("[tracker]\nrate_hz = 5000"),
            &["tracker.rate_hz", "5000", "1000"],
        ),
        (plus("[tracker]\nlatency = 60"), &["tracker.latency", "60"]),
        (
            plus("[output]\ngif_width = 100000"),
            &["output.gif_width", "7680"],
        ),
        // A tall screen makes a tall GIF from a modest width.
        (
            plus("[screen]\nsize = [0.1, 10.0]\n[arena]\nsize = [1.0, 1.0]"),
            &["output.gif_width", "48000"],
        ),
        (plus("[field]\ncell = 0.0001"), &["field.cell", "GB", "1e8"]),
        (
            GOOD.replace("count = 3", "count = 100001"),
            &["robots[0].count", "100000"],
        ),
    ]);
    let points = vec!["[0.1, 0.1]"; 100_001].join(", ");
    assert_refused(
        &with_map(&format!(
            "{{ polyline = [{points}], width = 0.01, rate = 1 }}"
        )),
        &["pheromones[0].maps[0].polyline", "100001 points"],
    );
    // Few points, but each wide segment covers the whole grid.
    let zigzag = (0..2000)
        .map(|k| format!("[{}, 0.4]", 0.1 + 0.0001 * (k % 2) as f32))
        .collect::<Vec<_>>()
        .join(", ");
    assert_refused(
        &format!(
            "{}\n[field]\ncell = 0.001\n",
            with_map(&format!(
                "{{ polyline = [{zigzag}], width = 3.0, rate = 1 }}"
            ))
        ),
        &["pheromones[0].maps[0].polyline", "visits"],
    );
    // Every robot's deposit kernel covers the whole fine grid.
    assert_refused(
        &format!(
            "{}\n[field]\ncell = 0.0005\n",
            with_robots(
                "count = 500\nbehaviour = \"avoid\"\n\
                 deposits = [{ pheromone = \"trail\", kernel = { shape = \"disc\", radius = 1.0 }, rate = 1 }]"
            )
        ),
        &["`robots[0].deposits[0].kernel.radius` = 1:", "1e9"],
    );
    // Every robot senses every source: 40,000 robots each emitting one is 1.6e9 pairs a step.
    let emitters = r#"
duration = 1.0
[arena]
size = [10.0, 10.0]
[[pheromones]]
name = "alarm"
colour = [255, 0, 0]
model = "gaussian"
evaporation = 5.0
[[robots]]
count = 40000
behaviour = "avoid"
emits = [{ pheromone = "alarm", k = 1, sigma = [0.1, 0.1], evaporation = 5 }]
"#;
    assert_refused(emitters, &["robots[0].emits", "1e9"]);
}

// Class 3: input that parses but means nothing is refused; half a table takes the defaults.

#[test]
fn arrays_of_the_wrong_length_are_refused() {
    assert_all_refused(&[
        (
            plus("[screen]\nresolution = [1920, 1080, 3]\nsize = [1.439, 0.809]"),
            &["screen.resolution", "expected 2 values, got 3"],
        ),
        (
            with_map("{ polyline = [[0.1, 0.1], [0.2, 0.2, 0.3]], width = 0.01, rate = 1 }"),
            &["pheromones[0].maps[0].polyline[1]", "got 3"],
        ),
        (
            with_robots(
                "count = 1\nbehaviour = \"avoid\"\nplacement = \"explicit\"\nposes = [[0.5, 0.5, 0.0, 1.0]]",
            ),
            &["robots[0].poses[0]", "expected 3"],
        ),
        (
            GOOD.replace("colour = [0, 0, 255]", "colour = [0, 0, 255, 1]"),
            &["pheromones[0].colour"],
        ),
    ]);
}

#[test]
fn robots_may_not_overlap_at_the_start() {
    let explicit = |poses: &str| {
        with_robots(&format!(
            "count = 2\nbehaviour = \"avoid\"\nplacement = \"explicit\"\nposes = {poses}"
        ))
    };
    assert_refused(
        &explicit("[[0.5, 0.5, 0.0], [0.5, 0.5, 90.0]]"),
        &["robots[0].poses[1]", "diameter"],
    );
    assert_refused(
        &explicit("[[0.5, 0.5, 0.0], [0.53, 0.5, 0.0]]"),
        &["robots[0].poses[1]", "diameter"],
    );
    check(
        &explicit("[[0.5, 0.5, 0.0], [0.541, 0.5, 0.0]]"),
        Path::new("."),
    )
    .expect("touching");
    // Across groups too.
    let two_groups = with_robots(
        "count = 1\nbehaviour = \"avoid\"\nplacement = \"explicit\"\nposes = [[0.5, 0.5, 0.0]]\n\
         [[robots]]\ncount = 1\nbehaviour = \"avoid\"\nplacement = \"explicit\"\nposes = [[0.51, 0.5, 0.0]]",
    );
    assert_refused(&two_groups, &["robots[1].poses[0]", "robots[0]"]);
}

#[test]
fn the_body_holds_its_wheels_and_sensors() {
    assert_all_refused(&[
        (
            plus("[robot]\nwheel_base = 0.05"),
            &["robot.wheel_base", "0.05"],
        ),
        (
            plus("[sensor]\nfootprint_radius = 0.01"),
            &["sensor.footprint_radius", "0.01"],
        ),
        (
            plus("[robot]\nradius = 0.012\nwheel_base = 0.02"),
            &["sensor.footprint_radius"],
        ),
    ]);
}

#[test]
fn durations_must_be_positive_numbers() {
    assert_all_refused(&[
        (
            GOOD.replace("duration = 1.0", "duration = nan"),
            &["duration", "NaN"],
        ),
        (
            GOOD.replace("duration = 1.0", "duration = -1.0"),
            &["duration", "-1"],
        ),
        (plus("[robot]\nmotor_lag = nan"), &["robot.motor_lag"]),
    ]);
    let sc = check(GOOD, Path::new(".")).unwrap();
    for bad in [f32::NAN, -1.0, 0.0, f32::INFINITY] {
        let e = sc.clone().with_overrides(None, Some(bad)).unwrap_err();
        assert!(e.to_string().contains("duration"), "{bad}: {e}");
    }
}

#[test]
fn half_a_screen_table_takes_the_defaults() {
    let only_size =
        check(&plus("[screen]\nsize = [1.0, 0.5]"), Path::new(".")).expect("size alone");
    assert_eq!(only_size.spec.screen.resolution, [3840, 2160]);
    assert_eq!(only_size.spec.screen.size, [1.0, 0.5]);
    let only_resolution = check(&plus("[screen]\nresolution = [1920, 1080]"), Path::new("."))
        .expect("resolution alone");
    assert_eq!(only_resolution.spec.screen.resolution, [1920, 1080]);
    assert_eq!(only_resolution.spec.screen.size, [1.439, 0.809]);
}
