//! Named scenarios the tests and benches share, built in code with `ScenarioBuilder`. Each is the
//! scenario one or more tests were written against: changing one changes what they check (and, for
//! [`large_swarm`], the golden hashes of `tests/golden.rs`).
use colcos_sim::field::Kernel;
use colcos_sim::scenario::{
    EmitSpec, MapSpec, PheromoneSpec, Placement, RobotGroupSpec, Scenario, ScenarioBuilder,
    SourceSpec,
};
use std::path::{Path, PathBuf};

/// The paper's 65-inch 4K panel: resolution (pixels) and size (m).
pub const PANEL: ([u32; 2], [f32; 2]) = ([3840, 2160], [1.439, 0.809]);

/// A small screen (720 x 400 pixels, 1.44 x 0.8 m) for sensing tests: coarse pixels, quick to draw.
pub const SMALL_SCREEN: ([u32; 2], [f32; 2]) = ([720, 400], [1.44, 0.8]);

fn valid(builder: ScenarioBuilder) -> Scenario {
    builder.build().expect("a preset scenario is valid")
}

/// Case I of the paper, shortened (4 s), for comparing backends: static maps of three pheromones
/// drawn on the grid (d = 0, steady state e J), six robots following the red one and laying a blue
/// trail.
pub fn case_i_like() -> Scenario {
    valid(three_maps(1e-6, 6).name("case_i_like").seed(3).cell(0.005))
}

/// The load of [`case_i_like`] on the 65-inch panel, 4 s: a red and a green static map (green
/// diffusing `green_diffusion` m^2/s), a blue pheromone, and `robots` robots following red and laying
/// blue on a cone. The name, the seed and the grid cell are the caller's.
pub fn three_maps(green_diffusion: f32, robots: usize) -> ScenarioBuilder {
    ScenarioBuilder::new()
        .duration(4.0)
        .screen(PANEL.0, PANEL.1)
        .pheromone(
            PheromoneSpec::grid("red", [255.0, 0.0, 0.0])
                .with_evaporation(5.0)
                .with_map(MapSpec::polyline(
                    vec![[0.2, 0.2], [1.2, 0.2], [1.2, 0.6]],
                    0.03,
                    0.2,
                )),
        )
        .pheromone(
            PheromoneSpec::grid("green", [0.0, 255.0, 0.0])
                .with_evaporation(8.0)
                .with_diffusion(green_diffusion)
                .with_map(MapSpec::polyline(
                    vec![[0.2, 0.6], [0.7, 0.4], [1.2, 0.6]],
                    0.05,
                    0.15,
                )),
        )
        .pheromone(PheromoneSpec::grid("blue", [40.0, 0.0, 255.0]).with_evaporation(3.0))
        .robots(
            follower(robots, "r")
                .with_param("sensitivity", 0.5)
                .with_param("threshold", 0.05)
                .with_deposit("blue", Kernel::Cone { radius: 0.012 }, 5.0),
        )
}

/// Case II of the paper, shortened (4 s), for comparing backends: a leader followed by an attractive
/// Gaussian pheromone (AGP), five followers that refresh a Gaussian source when near the leader
/// (ALP), and a diffusing grid trail the leader lays.
pub fn case_ii_like() -> Scenario {
    let agp = EmitSpec {
        rho: 0.3,
        ..EmitSpec::follow("agp", 0.4, [0.06, 0.04], 5.0)
    };
    valid(
        ScenarioBuilder::new()
            .name("case_ii_like")
            .duration(4.0)
            .seed(5)
            .screen(PANEL.0, PANEL.1)
            .cell(0.005)
            .pheromone(PheromoneSpec::gaussian("agp", [0.0, 255.0, 0.0]).with_evaporation(5.0))
            .pheromone(PheromoneSpec::gaussian("alp", [255.0, 0.0, 0.0]).with_evaporation(2.0))
            .pheromone(
                PheromoneSpec::grid("trail", [0.0, 0.0, 255.0])
                    .with_evaporation(10.0)
                    .with_diffusion(2e-6),
            )
            .robots(
                RobotGroupSpec::new(1, "wander")
                    .with_role("leader")
                    .with_emit(agp)
                    .with_deposit("trail", Kernel::Gaussian { sigma: 0.006 }, 4.0),
            )
            .robots(
                follower(5, "g")
                    .with_role("follower")
                    .with_param("sensitivity", 0.5)
                    .with_param("threshold", 0.05)
                    .with_emit(
                        EmitSpec::follow("alp", 0.2, [0.03, 0.03], 2.0).when_near("leader", 0.3),
                    ),
            ),
    )
}

/// `count` robots following colour channel `channel` at 0.1 m/s.
fn follower(count: usize, channel: &str) -> RobotGroupSpec {
    RobotGroupSpec::new(count, "follow")
        .with_param("channel", channel)
        .with_param("speed", 0.1)
}

/// Enough robots and deposits on a fine grid (3 mm, 2.4 x 1.35 m) that every parallel path of a run
/// is taken (robots, banded deposits, field rows): 200 robots follow a static blue trail laying red,
/// 150 avoid each other laying blue; 0.4 s with a GIF frame every 0.2 s. `tests/golden.rs` pins
/// every file its run writes; `tests/determinism.rs` runs it longer on 1, 2 and 4 threads.
pub fn large_swarm() -> ScenarioBuilder {
    ScenarioBuilder::new()
        .duration(0.4)
        .seed(7)
        .screen([3840, 2160], [2.4, 1.35])
        .cell(0.003)
        .gif_interval(0.2)
        .pheromone(
            PheromoneSpec::grid("red", [255.0, 0.0, 0.0])
                .with_evaporation(5.0)
                .with_diffusion(1e-5),
        )
        .pheromone(
            PheromoneSpec::grid("blue", [0.0, 0.0, 255.0])
                .with_evaporation(5.0)
                .with_diffusion(1e-6)
                .with_map(MapSpec::polyline(vec![[0.2, 0.2], [2.2, 1.1]], 0.05, 0.2)),
        )
        .robots(
            RobotGroupSpec::new(200, "follow")
                .with_param("channel", "b")
                .with_deposit("red", Kernel::Cone { radius: 0.01 }, 5.0),
        )
        .robots(RobotGroupSpec::new(150, "avoid").with_deposit(
            "blue",
            Kernel::Disc { radius: 0.01 },
            5.0,
        ))
}

/// The live loop's benchmark load: 100 robots on the 65-inch panel following a static blue trail and
/// laying red, over three diffusing 5 mm grids (red, green, blue).
pub fn three_grids_panel() -> Scenario {
    let diffusing = |name: &str, colour: [f32; 3]| {
        PheromoneSpec::grid(name, colour)
            .with_evaporation(20.0)
            .with_diffusion(1e-6)
    };
    valid(
        ScenarioBuilder::new()
            .duration(10.0)
            .cell(0.005)
            .pheromone(diffusing("red", [255.0, 0.0, 0.0]))
            .pheromone(diffusing("green", [0.0, 255.0, 0.0]))
            .pheromone(
                PheromoneSpec::grid("blue", [0.0, 0.0, 255.0])
                    .with_evaporation(60.0)
                    .with_map(MapSpec::polyline(vec![[0.2, 0.2], [1.2, 0.6]], 0.03, 0.05)),
            )
            .robots(
                RobotGroupSpec::new(100, "follow")
                    .with_param("channel", "b")
                    .with_deposit("red", Kernel::Disc { radius: 0.01 }, 5.0),
            ),
    )
}

/// `count` robots following a blue grid trail (`trail`, 20 s evaporation) at 0.1 m/s and laying it,
/// 3 units/s over a 1 cm disc: the benches' load for sensing and contacts. 10 s, no GIF; the screen,
/// the grid and anything else are the caller's.
pub fn trail_followers(count: usize) -> ScenarioBuilder {
    ScenarioBuilder::new()
        .duration(10.0)
        .gif_interval(0.0)
        .pheromone(PheromoneSpec::grid("trail", [0.0, 0.0, 255.0]).with_evaporation(20.0))
        .robots(follower(count, "b").with_deposit("trail", Kernel::Disc { radius: 0.01 }, 3.0))
}

/// An orange glow: one fixed Gaussian source of `k` units, `sigma` (m) wide, at the centre of
/// [`SMALL_SCREEN`], that practically never evaporates.
pub fn orange_glow(k: f32, sigma: [f32; 2]) -> PheromoneSpec {
    PheromoneSpec::gaussian("glow", [200.0, 120.0, 60.0])
        .with_evaporation(1e6)
        .with_source(SourceSpec {
            k,
            sigma,
            rho: 0.0,
            evaporation: 1e6,
            centre: [0.72, 0.4],
            start: 0.0,
        })
}

/// Two robots near the centre of [`SMALL_SCREEN`], which one wide glow paints an almost uniform
/// orange, reading it through the colour calibration file `calibration` without sensor noise; 1 s.
pub fn glow_pair(calibration: &str) -> ScenarioBuilder {
    ScenarioBuilder::new()
        .duration(1.0)
        .seed(3)
        .screen(SMALL_SCREEN.0, SMALL_SCREEN.1)
        .with(|s| s.sensor.noise = 0.0)
        .pheromone(orange_glow(3.77, [1.0, 1.0]))
        .robots(RobotGroupSpec::new(2, "wander").at_poses(vec![[0.62, 0.4, 0.0], [0.82, 0.4, 0.0]]))
        .with(|s| s.rig.colour_calibration = Some(calibration.to_string()))
}

/// A green Gaussian pheromone `a` the calibration scenarios carry (nothing emits it).
fn quiet_green() -> PheromoneSpec {
    PheromoneSpec::gaussian("a", [0.0, 255.0, 0.0]).with_evaporation(5.0)
}

/// Robots parked at `poses` (x m, y m, heading degrees) on the 65-inch panel, for calibrating the rig
/// on the twin: 60 s, seed 5. The `[rig]` calibration files are the caller's.
pub fn parked(poses: &[[f32; 3]]) -> ScenarioBuilder {
    ScenarioBuilder::new()
        .name("calibration")
        .duration(60.0)
        .seed(5)
        .pheromone(quiet_green())
        .robots(RobotGroupSpec::new(poses.len(), "wander").at_poses(poses.to_vec()))
}

/// Six robots wandering at `speed` m/s over a grid in the middle of the 65-inch panel, tracked every
/// 20 ms step without a delay of the tracker model's own: 60 s, seed 8.
pub fn wanderers(speed: f64) -> Scenario {
    valid(
        ScenarioBuilder::new()
            .name("wanderers")
            .duration(60.0)
            .seed(8)
            .with(|s| {
                s.tracker.rate_hz = 50.0;
                s.tracker.latency = 0.0;
                s.tracker.dropout = 0.0;
            })
            .pheromone(quiet_green())
            .robots(
                RobotGroupSpec::new(6, "wander")
                    .with_param("speed", speed)
                    .with_placement(Placement::Grid)
                    .in_region([0.2, 0.2, 1.2, 0.6]),
            ),
    )
}

/// The TOML files in the repository's folders `dirs` (e.g. `scenarios`, `scenarios/sweeps`),
/// sorted: the scenario and sweep files shipped with it.
pub fn shipped(dirs: &[&str]) -> Vec<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut files: Vec<PathBuf> = dirs
        .iter()
        .flat_map(|d| std::fs::read_dir(root.join(d)).unwrap().flatten())
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    files.sort();
    files
}

/// The manifest of the policy exported for the on-board tests (`bridge/tests/data/onboard`, written
/// by `scripts/onboard_fixture.py`: both wheels at half the largest wheel speed, the left one slowed
/// by the front-left bumper).
pub fn onboard_policy() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../bridge/tests/data/onboard/policy.json")
}

/// Three robots heading along x from `x` (at y = 0.2, 0.4, 0.6 m) that carry the policy exported to
/// `onboard` (its manifest); the rig's shield caps the wheels at 0.2 m/s. A 960 x 540 screen, 60 s.
pub fn onboard(onboard: &Path, x: f32) -> Scenario {
    valid(
        ScenarioBuilder::new()
            .name("onboard")
            .duration(60.0)
            .dt(0.02)
            .seed(3)
            .screen([960, 540], PANEL.1)
            .robots(RobotGroupSpec::new(3, "wander").at_poses(vec![
                [x, 0.2, 0.0],
                [x, 0.4, 0.0],
                [x, 0.6, 0.0],
            ]))
            .with(|s| {
                s.rig.onboard = Some(onboard.display().to_string());
                s.rig.shield.max_wheel_speed = 0.2;
            }),
    )
}
