//! Where a large swarm's step goes: times whole steps of the 10,000-robot benchmark scenario with
//! parts switched off. `cargo run --release --example profile_swarm`
use colcos::sim::prelude::*;
use std::time::Instant;

fn time(label: &str, text: &str) {
    let sc = Scenario::from_toml_str(text, ".").unwrap();
    let mut w = World::new(&sc).unwrap();
    for _ in 0..3 {
        w.step();
    }
    let mut xs: Vec<f64> = (0..15)
        .map(|_| {
            let t = Instant::now();
            w.step();
            t.elapsed().as_secs_f64() * 1e3
        })
        .collect();
    xs.sort_by(f64::total_cmp);
    println!("{label:40} {:8.2} ms", xs[xs.len() / 2]);
}

fn main() {
    let base = |robots: usize, behaviour: &str, pheromones: bool, deposits: bool, physics: &str| {
        let ph = if pheromones {
            "[[pheromones]]\nname = \"red\"\ncolour = [255, 0, 0]\nevaporation = 20.0\ndiffusion = 1e-6\n[[pheromones]]\nname = \"green\"\ncolour = [0, 255, 0]\nevaporation = 20.0\n[[pheromones]]\nname = \"blue\"\ncolour = [0, 0, 255]\nevaporation = 20.0\n"
        } else {
            ""
        };
        let dep = if deposits {
            "deposits = [{ pheromone = \"red\", kernel = { shape = \"disc\", radius = 0.01 }, rate = 3.0 }]"
        } else {
            ""
        };
        format!(
            "duration = 10.0\nphysics = \"{physics}\"\n[screen]\nresolution = [38400, 21600]\nsize = [14.4, 8.1]\n[field]\ncell = 0.01\n{ph}\n[[robots]]\ncount = {robots}\nbehaviour = \"{behaviour}\"\n{dep}\n"
        )
    };
    time(
        "full (follow, 3 fields, deposits, discs)",
        &base(10_000, "follow", true, true, "discs"),
    );
    time("no deposits", &base(10_000, "follow", true, false, "discs"));
    time(
        "no pheromones (sensing empty list)",
        &base(10_000, "avoid", false, false, "discs"),
    );
    time(
        "full with rapier",
        &base(10_000, "follow", true, true, "rapier"),
    );
    time(
        "1,000 robots full discs",
        &base(1_000, "follow", true, true, "discs"),
    );
}
