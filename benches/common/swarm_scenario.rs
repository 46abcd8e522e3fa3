//! The scenario of `cargo bench --bench swarm_step`, shared with `examples/profile_swarm.rs` (which
//! includes this file) so that a profile looks at exactly what the bench times: robots in three equal
//! groups, each laying one of three diffusing pheromones and following another.
use colcos::sim::prelude::*;

pub fn scenario(
    robots: usize,
    size: [f32; 2],
    resolution: [u32; 2],
    cell: f32,
    physics: &str,
) -> Scenario {
    let per_group = robots / 3;
    let group = |lay: &str, follow: &str, count: usize| {
        format!(
            r#"
[[robots]]
count = {count}
behaviour = "follow"
params = {{ channel = "{follow}", speed = 0.1 }}
deposits = [{{ pheromone = "{lay}", kernel = {{ shape = "disc", radius = 0.01 }}, rate = 3.0 }}]
"#
        )
    };
    let text = format!(
        r#"
duration = 10.0
physics = "{physics}"
[screen]
resolution = [{rx}, {ry}]
size = [{w}, {h}]
[field]
cell = {cell}
[output]
gif_interval = 0
[[pheromones]]
name = "red"
colour = [255, 0, 0]
evaporation = 20.0
diffusion = 1e-6
[[pheromones]]
name = "green"
colour = [0, 255, 0]
evaporation = 20.0
diffusion = 1e-6
[[pheromones]]
name = "blue"
colour = [0, 0, 255]
evaporation = 20.0
diffusion = 1e-6
{a}{b}{c}"#,
        rx = resolution[0],
        ry = resolution[1],
        w = size[0],
        h = size[1],
        a = group("red", "b", per_group),
        b = group("green", "r", per_group),
        c = group("blue", "g", robots - 2 * per_group),
    );
    Scenario::from_toml_str(&text, ".").expect("bench scenario is valid")
}
