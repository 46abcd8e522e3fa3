//! Timing of the arena physics (not a pass/fail test): run with
//! `cargo test --release -p colcos-sim --test robot_timing -- --ignored --nocapture`.
use colcos_sim::robot::{ArenaPhysics, ColiasParams, PhysicsBackend, Pose};
use glam::Vec2;
use std::time::Instant;

fn median_step_ms(n: usize, size: Vec2, backend: PhysicsBackend) -> f64 {
    let p = ColiasParams::default();
    let cols = ((n as f32 * size.x / size.y).sqrt().ceil() as usize).max(1);
    let rows = n.div_ceil(cols);
    let (dx, dy) = (size.x / cols as f32, size.y / rows as f32);
    let poses: Vec<Pose> = (0..n)
        .map(|i| {
            let (c, r) = (i % cols, i / cols);
            Pose::new(
                (c as f32 + 0.5) * dx,
                (r as f32 + 0.5) * dy,
                (i as f32 * 2.39) % 6.0,
            )
        })
        .collect();
    let mut phys = ArenaPhysics::with_backend(size, &p, &poses, backend);
    let mut s = 7u32;
    let mut next = move || {
        s = s.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        (s >> 8) as f32 / (1u32 << 24) as f32
    };
    let mut v: Vec<(f32, f32)> = vec![(0.0, 0.0); n];
    let mut times = Vec::new();
    for k in 0..400 {
        if k % 25 == 0 {
            for x in v.iter_mut() {
                *x = (0.35 * next(), 8.0 * (next() - 0.5));
            }
        }
        let t = Instant::now();
        phys.step(&v, 0.02);
        if k >= 100 || std::env::var("ROBOT_TIMING_TRACE").is_ok() {
            times.push(t.elapsed().as_secs_f64() * 1e3);
        }
    }
    if std::env::var("ROBOT_TIMING_TRACE").is_ok() {
        for (i, c) in times.chunks(50).enumerate() {
            let mut c = c.to_vec();
            c.sort_by(|a, b| a.partial_cmp(b).unwrap());
            eprintln!(
                "  steps {}..: median {:.3} ms",
                100 + 50 * i,
                c[c.len() / 2]
            );
        }
    }
    times.sort_by(|a, b| a.partial_cmp(b).unwrap());
    times[times.len() / 2]
}

#[test]
#[ignore]
fn physics_step_timing() {
    let only: Option<usize> = std::env::var("ROBOT_TIMING_N")
        .ok()
        .and_then(|v| v.parse().ok());
    let mut cases = vec![
        (100, Vec2::new(1.44, 0.81)),
        (1_000, Vec2::new(14.4, 8.1)),
        (10_000, Vec2::new(14.4, 8.1)),
    ];
    if std::env::var("ROBOT_TIMING_SCALING").is_ok() {
        // Constant density (10,000 in 14.4 x 8.1 m).
        cases = [1_000, 2_000, 4_000, 10_000]
            .iter()
            .map(|&n| (n, Vec2::new(14.4, 8.1) * (n as f32 / 10_000.0).sqrt()))
            .collect();
    }
    for (n, size) in cases.into_iter() {
        if only.is_some_and(|o| o != n) {
            continue;
        }
        for backend in [PhysicsBackend::Rapier, PhysicsBackend::Discs] {
            if std::env::var("ROBOT_TIMING_DISCS").is_ok() && backend == PhysicsBackend::Rapier {
                continue;
            }
            let ms = median_step_ms(n, size, backend);
            eprintln!(
                "{backend:?}: {n} robots in {:?} m: median step {ms:.3} ms",
                size
            );
        }
    }
}
