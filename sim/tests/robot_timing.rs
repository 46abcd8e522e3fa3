//! Timing of the arena physics (not a pass/fail test): run with
//! `cargo test --release -p colcos-sim --test robot_timing -- --ignored --nocapture`.
use colcos_sim::robot::{ArenaPhysics, ColiasParams, Pose};
use glam::Vec2;
use std::time::Instant;

fn median_step_ms(n: usize, size: Vec2) -> f64 {
    let p = ColiasParams::default();
    let cols = ((n as f32 * size.x / size.y).sqrt().ceil() as usize).max(1);
    let rows = n.div_ceil(cols);
    let (dx, dy) = (size.x / cols as f32, size.y / rows as f32);
    let poses: Vec<Pose> = (0..n)
        .map(|i| {
            let (c, r) = (i % cols, i / cols);
            Pose::new((c as f32 + 0.5) * dx, (r as f32 + 0.5) * dy, (i as f32 * 2.39) % 6.28)
        })
        .collect();
    let mut phys = ArenaPhysics::new(size, &p, &poses);
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
        if k >= 100 {
            times.push(t.elapsed().as_secs_f64() * 1e3);
        }
    }
    times.sort_by(|a, b| a.partial_cmp(b).unwrap());
    times[times.len() / 2]
}

#[test]
#[ignore]
fn physics_step_timing() {
    for (n, size) in [(100, Vec2::new(1.44, 0.81)), (1_000, Vec2::new(1.44, 0.81)), (1_000, Vec2::new(14.4, 8.1)), (10_000, Vec2::new(14.4, 8.1))] {
        eprintln!("{n} robots in {:?} m: median step {:.3} ms", size, median_step_ms(n, size));
    }
}
