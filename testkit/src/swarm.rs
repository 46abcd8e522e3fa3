//! The scenario of `cargo bench --bench swarm_step`, shared with `examples/profile_swarm.rs` so that a
//! profile looks at exactly what the bench times: robots in three equal groups, each laying one of
//! three diffusing pheromones and following another.
use colcos_sim::field::Kernel;
use colcos_sim::robot::PhysicsBackend;
use colcos_sim::scenario::{PheromoneSpec, RobotGroupSpec, Scenario, ScenarioBuilder};

/// `robots` robots on a screen of `size` m shown at `resolution`, on a grid of `cell` m, their
/// contacts solved by `physics`; 10 s, no GIF.
pub fn scenario(
    robots: usize,
    size: [f32; 2],
    resolution: [u32; 2],
    cell: f32,
    physics: PhysicsBackend,
) -> Scenario {
    let per_group = robots / 3;
    let pheromone = |name: &str, colour: [f32; 3]| {
        PheromoneSpec::grid(name, colour)
            .with_evaporation(20.0)
            .with_diffusion(1e-6)
    };
    let group = |lay: &str, follow: &str, count: usize| {
        RobotGroupSpec::new(count, "follow")
            .with_param("channel", follow)
            .with_param("speed", 0.1)
            .with_deposit(lay, Kernel::Disc { radius: 0.01 }, 3.0)
    };
    ScenarioBuilder::new()
        .duration(10.0)
        .physics(physics)
        .screen(resolution, size)
        .cell(cell)
        .gif_interval(0.0)
        .pheromone(pheromone("red", [255.0, 0.0, 0.0]))
        .pheromone(pheromone("green", [0.0, 255.0, 0.0]))
        .pheromone(pheromone("blue", [0.0, 0.0, 255.0]))
        .robots(group("red", "b", per_group))
        .robots(group("green", "r", per_group))
        .robots(group("blue", "g", robots - 2 * per_group))
        .build()
        .expect("bench scenario is valid")
}
