//! Whole-world steps: 10,000 Colias robots (colour sensors, bumpers, trail injection) on a 1 cm
//! three-pheromone grid in a 14.4 m x 8.1 m arena (the density of 100 robots on the 65-inch screen),
//! and 100 robots on the 65-inch screen with a 5 mm grid. Prints the median step time, the real-time
//! factor at dt = 20 ms, and the ratio to ARGoS's headline (10,000 simple robots at 1.4x real time).
//!
//! cargo bench --bench swarm_step
use colcos::sim::prelude::*;
use colcos::sim::robot::PhysicsBackend::{Discs, Rapier};
use colcos_testkit::swarm::scenario;
use criterion::{Criterion, criterion_group, criterion_main};
use std::time::{Duration, Instant};

const ARGOS_10K_REAL_TIME_FACTOR: f64 = 1.4;

fn median(mut xs: Vec<f64>) -> f64 {
    xs.sort_by(f64::total_cmp);
    xs[xs.len() / 2]
}

/// Median wall time of one step over `n` steps after `warm` warm-up steps.
fn time_steps(world: &mut World, warm: usize, n: usize) -> f64 {
    for _ in 0..warm {
        world.step();
    }
    median(
        (0..n)
            .map(|_| {
                let t = Instant::now();
                world.step();
                t.elapsed().as_secs_f64()
            })
            .collect(),
    )
}

fn report(label: &str, step_s: f64, dt: f64, target: f64, peer: Option<(&str, f64)>) {
    let rtf = dt / step_s;
    print!(
        "{label}: median step {:.3} ms, {rtf:.1}x real time (target >= {target}x: {})",
        step_s * 1e3,
        if rtf >= target { "met" } else { "NOT met" }
    );
    if let Some((name, peer_rtf)) = peer {
        print!(", {:.1}x {name}", rtf / peer_rtf);
    }
    println!();
}

fn bench(c: &mut Criterion) {
    let big = scenario(10_000, [14.4, 8.1], [38_400, 21_600], 0.01, Discs);
    let big_rapier = scenario(10_000, [14.4, 8.1], [38_400, 21_600], 0.01, Rapier);
    let small = scenario(100, [1.439, 0.809], [3840, 2160], 0.005, Rapier);
    let mut w_big = World::new(&big).unwrap();
    let mut w_big_rapier = World::new(&big_rapier).unwrap();
    let mut w_small = World::new(&small).unwrap();

    let mut g = c.benchmark_group("swarm_step");
    g.sample_size(20)
        .measurement_time(Duration::from_secs(8))
        .warm_up_time(Duration::from_secs(2));
    g.bench_function("10k_robots_1cm_grid_discs", |b| b.iter(|| w_big.step()));
    g.bench_function("10k_robots_1cm_grid_rapier", |b| {
        b.iter(|| w_big_rapier.step())
    });
    g.bench_function("100_robots_5mm_grid", |b| b.iter(|| w_small.step()));
    g.finish();

    println!(
        "\n== swarm_step summary (dt = 20 ms, {} threads) ==",
        rayon::current_num_threads()
    );
    let argos = Some(("ARGoS (10,000 robots at 1.4x)", ARGOS_10K_REAL_TIME_FACTOR));
    // (label, world, warm-up steps, timed steps, real-time factor to reach, peer to compare with)
    let runs = [
        (
            "10,000 robots, 14.4 x 8.1 m, 1 cm grid x3, disc solver",
            &mut w_big,
            10,
            100,
            2.0,
            argos,
        ),
        (
            "10,000 robots, 14.4 x 8.1 m, 1 cm grid x3, rapier",
            &mut w_big_rapier,
            5,
            30,
            2.0,
            argos,
        ),
        (
            "100 robots, 65-inch screen, 5 mm grid x3",
            &mut w_small,
            50,
            2000,
            100.0,
            None,
        ),
    ];
    for (label, world, warm, n, target, peer) in runs {
        report(label, time_steps(world, warm, n), 0.02, target, peer);
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().without_plots();
    targets = bench
}
criterion_main!(benches);
