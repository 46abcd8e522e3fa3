//! `[[pheromones]] preload = true`: a grid field starts at the steady state `e J` of its static maps,
//! stays there while the maps inject, and a key that cannot be honoured is named in the error.
use colcos_sim::field::FieldModel;
use colcos_sim::prelude::*;
use colcos_testkit::parsing::assert_all_refused;

const SCENARIO: &str = r#"
name = "preload"
duration = 1.0
[screen]
size = [0.4, 0.3]
[field]
cell = 0.01
[[pheromones]]
name = "lap"
colour = [0.0, 0.0, 255.0]
evaporation = 50.0
preload = true
maps = [{ polyline = [[0.05, 0.15], [0.35, 0.15]], width = 0.04, rate = 0.02 }]
[[robots]]
count = 1
behaviour = "forage"
placement = "explicit"
poses = [[0.05, 0.15, 0.0]]
"#;

fn values(world: &World) -> Vec<f32> {
    match &world.pheromones()[0].model {
        FieldModel::Grid(g) => g.values().to_vec(),
        _ => panic!("a grid field"),
    }
}

#[test]
fn starts_at_e_j_and_stays_there() {
    let sc = Scenario::from_toml_str(SCENARIO, ".").unwrap();
    let mut world = World::new(&sc).unwrap();
    let v0 = values(&world);
    let peak = v0.iter().cloned().fold(0.0f32, f32::max);
    // e J = 50 s * 0.02 /s = 1 on the trail's centre line, 0 away from it.
    assert!((peak - 1.0).abs() < 1e-5, "peak {peak}");
    assert!(v0.iter().filter(|&&v| v == 0.0).count() > v0.len() / 2);
    for _ in 0..20 {
        world.step();
    }
    let v1 = values(&world);
    let drift = v0
        .iter()
        .zip(&v1)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0f32, f32::max);
    assert!(drift < 1e-5, "moved by {drift}");
    // Without the key the same field starts empty.
    let plain = SCENARIO.replace("preload = true\n", "");
    let world = World::new(&Scenario::from_toml_str(&plain, ".").unwrap()).unwrap();
    assert!(values(&world).iter().all(|&v| v == 0.0));
}

#[test]
fn preload_needs_maps_evaporation_and_no_diffusion() {
    let map = "maps = [{ polyline = [[0.05, 0.15], [0.35, 0.15]], width = 0.04, rate = 0.02 }]\n";
    assert_all_refused(&[
        (
            SCENARIO.replace("evaporation = 50.0\n", ""),
            &["pheromones[0].preload", "evaporation"],
        ),
        (
            SCENARIO.replace(
                "evaporation = 50.0\n",
                "evaporation = 50.0\ndiffusion = 1e-5\n",
            ),
            &["pheromones[0].preload", "diffusion"],
        ),
        (
            SCENARIO.replace(map, ""),
            &["pheromones[0].preload", "maps"],
        ),
        (
            SCENARIO.replace("preload = true", "preload = 1"),
            &["preload"],
        ),
    ]);
}
