//! Where a large swarm's step goes: times whole steps of the 10,000-robot benchmark scenario with
//! parts switched off. `cargo run --release --example profile_swarm [LABEL-WORD]` (environment:
//! `PROFILE_STEPS=N` to time N steps per case instead of 60).
use colcos::sim::field::Kernel;
use colcos::sim::prelude::*;
use colcos::sim::robot::PhysicsBackend::{self, Discs, Rapier};
use colcos::sim::scenario::{PheromoneSpec, RobotGroupSpec, ScenarioBuilder};
use colcos_testkit::swarm;
use std::time::Instant;

fn time(label: &str, scenario: ScenarioBuilder) {
    time_scenario(label, || scenario.build().unwrap());
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

/// `robots` running `behaviour` in the 10,000-robot benchmark's arena on a 1 cm grid, with or without
/// the three pheromones (red diffusing) and a red trail behind every robot.
fn case(
    robots: usize,
    behaviour: &str,
    pheromones: bool,
    deposits: bool,
    physics: PhysicsBackend,
) -> ScenarioBuilder {
    let mut b = ScenarioBuilder::new()
        .duration(10.0)
        .physics(physics)
        .screen([38_400, 21_600], [14.4, 8.1])
        .cell(0.01);
    if pheromones {
        let pheromone =
            |name: &str, colour| PheromoneSpec::grid(name, colour).with_evaporation(20.0);
        b = b
            .pheromone(pheromone("red", [255.0, 0.0, 0.0]).with_diffusion(1e-6))
            .pheromone(pheromone("green", [0.0, 255.0, 0.0]))
            .pheromone(pheromone("blue", [0.0, 0.0, 255.0]));
    }
    let mut group = RobotGroupSpec::new(robots, behaviour);
    if deposits {
        group = group.with_deposit("red", Kernel::Disc { radius: 0.01 }, 3.0);
    }
    b.robots(group)
}

fn main() {
    // Exactly what `cargo bench --bench swarm_step` steps.
    time_scenario("bench: 10,000 robots, discs", || {
        swarm::scenario(10_000, [14.4, 8.1], [38_400, 21_600], 0.01, Discs)
    });
    time_scenario("bench: 10,000 robots, rapier", || {
        swarm::scenario(10_000, [14.4, 8.1], [38_400, 21_600], 0.01, Rapier)
    });
    time_scenario("bench: 100 robots, 65-inch, 5 mm, rapier", || {
        swarm::scenario(100, [1.439, 0.809], [3840, 2160], 0.005, Rapier)
    });
    time(
        "full (follow, 3 fields, deposits, discs)",
        case(10_000, "follow", true, true, Discs),
    );
    time(
        "full on a 10 cm grid (fields in cache)",
        case(10_000, "follow", true, true, Discs).cell(0.1),
    );
    time("no deposits", case(10_000, "follow", true, false, Discs));
    time(
        "no pheromones (sensing empty list)",
        case(10_000, "avoid", false, false, Discs),
    );
    time(
        "full with rapier",
        case(10_000, "follow", true, true, Rapier),
    );
    // The 65-inch screen of the scenario files' default.
    let small = |physics| {
        case(100, "follow", true, true, physics)
            .screen([3840, 2160], [1.439, 0.809])
            .cell(0.005)
    };
    time("100 robots, 65-inch, 5 mm, rapier", small(Rapier));
    time("100 robots, 65-inch, 5 mm, discs", small(Discs));
    time(
        "1,000 robots full discs",
        case(1_000, "follow", true, true, Discs),
    );
}
