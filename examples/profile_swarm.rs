//! Where a large swarm's step goes: times whole steps of the 10,000-robot benchmark scenario with
//! parts switched off. `cargo run --release --example profile_swarm [LABEL-WORD]` (environment:
//! `PROFILE_STEPS=N` to time N steps per case instead of 60).
use colcos::sim::prelude::*;
use std::time::Instant;
#[path = "../benches/common/swarm_scenario.rs"]
mod swarm_scenario;

fn time(label: &str, text: &str) {
    time_scenario(label, || Scenario::from_toml_str(text, ".").unwrap());
}

fn time_scenario(label: &str, scenario: impl FnOnce() -> Scenario) {
    // `profile_swarm WORD` runs only the cases whose label contains WORD (for `perf record`).
    if let Some(only) = std::env::args().nth(1)
        && !label.contains(&only)
    {
        return;
    }
    let sc = scenario();
    let mut w = World::new(&sc).unwrap();
    for _ in 0..3 {
        w.step();
    }
    // PROFILE_STEPS=N times N steps instead of 60 (small worlds need thousands for a steady median).
    let steps = std::env::var("PROFILE_STEPS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(60);
    let cpu0 = process_cpu_seconds();
    let mut xs: Vec<f64> = (0..steps)
        .map(|_| {
            let t = Instant::now();
            w.step();
            t.elapsed().as_secs_f64() * 1e3
        })
        .collect();
    let cpu_ms = cpu0.and_then(|c0| Some((process_cpu_seconds()? - c0) * 1e3 / steps as f64));
    xs.sort_by(f64::total_cmp);
    // The fastest step is the steadiest figure on a shared machine (others' load only adds time).
    println!(
        "{label:40} {:8.2} ms wall (median), {:8.2} ms (fastest), {} ms CPU (mean, all threads)",
        xs[xs.len() / 2],
        xs[0],
        cpu_ms.map_or("?".into(), |c| format!("{c:.1}"))
    );
}

/// User + system CPU time of this process from /proc (Linux; 10 ms ticks). On a shared machine the CPU
/// time per step is a steadier figure than the wall time.
fn process_cpu_seconds() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    // Fields after the command name (which is in parentheses): utime and stime are fields 14 and 15.
    let rest = &stat[stat.rfind(')')? + 2..];
    let f: Vec<&str> = rest.split_whitespace().collect();
    let ticks: f64 = f.get(11)?.parse::<f64>().ok()? + f.get(12)?.parse::<f64>().ok()?;
    Some(ticks / 100.0)
}

const PHEROMONES: &str = "[[pheromones]]\nname = \"red\"\ncolour = [255, 0, 0]\nevaporation = 20.0\ndiffusion = 1e-6\n[[pheromones]]\nname = \"green\"\ncolour = [0, 255, 0]\nevaporation = 20.0\n[[pheromones]]\nname = \"blue\"\ncolour = [0, 0, 255]\nevaporation = 20.0\n";
const DEPOSITS: &str = "deposits = [{ pheromone = \"red\", kernel = { shape = \"disc\", radius = 0.01 }, rate = 3.0 }]";

fn main() {
    let base_cell = |robots: usize,
                     behaviour: &str,
                     pheromones: bool,
                     deposits: bool,
                     physics: &str,
                     cell: f32| {
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
            "duration = 10.0\nphysics = \"{physics}\"\n[screen]\nresolution = [38400, 21600]\nsize = [14.4, 8.1]\n[field]\ncell = {cell}\n{ph}\n[[robots]]\ncount = {robots}\nbehaviour = \"{behaviour}\"\n{dep}\n"
        )
    };
    let base = |robots: usize, behaviour: &str, pheromones: bool, deposits: bool, physics: &str| {
        base_cell(robots, behaviour, pheromones, deposits, physics, 0.01)
    };
    // Exactly what `cargo bench --bench swarm_step` steps.
    time_scenario("bench: 10,000 robots, discs", || {
        swarm_scenario::scenario(10_000, [14.4, 8.1], [38_400, 21_600], 0.01, "discs")
    });
    time_scenario("bench: 100 robots, 65-inch, 5 mm, rapier", || {
        swarm_scenario::scenario(100, [1.439, 0.809], [3840, 2160], 0.005, "rapier")
    });
    time(
        "full (follow, 3 fields, deposits, discs)",
        &base(10_000, "follow", true, true, "discs"),
    );
    time(
        "full on a 10 cm grid (fields in cache)",
        &base_cell(10_000, "follow", true, true, "discs", 0.1),
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
    let small = |physics: &str| {
        format!(
            "duration = 10.0\nphysics = \"{physics}\"\n[field]\ncell = 0.005\n{PHEROMONES}\n[[robots]]\ncount = 100\nbehaviour = \"follow\"\n{DEPOSITS}\n"
        )
    };
    time("100 robots, 65-inch, 5 mm, rapier", &small("rapier"));
    time("100 robots, 65-inch, 5 mm, discs", &small("discs"));
    time(
        "1,000 robots full discs",
        &base(1_000, "follow", true, true, "discs"),
    );
}
