//! A running world steps without allocating: every buffer of the simulator is sized when the world is
//! built or grown in its first steps, then reused. rapier's pipeline is the exception: it allocates a
//! few small blocks in each step with contacts (its solver's stage sync, its lists of modified bodies).
use colcos_sim::prelude::*;
use colcos_sim::robot::PhysicsBackend;
use colcos_testkit::alloc::{Counting, allocations, assert_installed};
use colcos_testkit::threads::on_threads;

#[global_allocator]
static ALLOCATOR: Counting = Counting;

const SCENARIOS: [&str; 6] = [
    "three_trails.toml",
    "case1_g3.toml",
    "case2_alarm.toml",
    "maze_trail.toml",
    "printed_track.toml",
    "rig_100.toml",
];

/// Allocations per step over 300 steps of a shipped scenario after 300 steps to warm up, stepped
/// inside a rayon pool (from outside one, rayon's job queue allocates a block every 63 jobs that a
/// large world hands it).
fn allocations_per_step(file: &str, physics: PhysicsBackend) -> f64 {
    let path = format!("{}/../scenarios/{file}", env!("CARGO_MANIFEST_DIR"));
    let mut sc = Scenario::from_file(&path).unwrap();
    sc.spec.physics = physics;
    on_threads(2, || {
        let mut w = World::new(&sc).unwrap();
        for _ in 0..300 {
            w.step();
        }
        let before = allocations();
        let steps = 300;
        for _ in 0..steps {
            w.step();
        }
        (allocations() - before) as f64 / steps as f64
    })
}

/// With the disc solver nothing allocates in a step (rayon's own work queues may grow now and then in
/// a large world: under one block in twenty steps). With rapier, only its pipeline's few blocks a step
/// (measured: 2.4-3.4 in the small worlds, 8.7 with 100 robots): at most four, and one more per ten
/// robots. One test, as the counter counts every thread's allocations.
#[test]
fn a_running_world_steps_without_allocating() {
    assert_installed();
    for file in SCENARIOS {
        let per_step = allocations_per_step(file, PhysicsBackend::Discs);
        assert!(
            per_step < 0.05,
            "{file}, discs: {per_step} allocations a step"
        );
        let per_step = allocations_per_step(file, PhysicsBackend::Rapier);
        let path = format!("{}/../scenarios/{file}", env!("CARGO_MANIFEST_DIR"));
        let robots = Scenario::from_file(&path).unwrap().robot_count();
        // A debug build's rapier allocates more (5.8 a step in three_trails against 3.4): twice
        // the bound there.
        let slack = if cfg!(debug_assertions) { 2.0 } else { 1.0 };
        let bound = (4.0 + robots as f64 / 10.0) * slack;
        assert!(
            per_step <= bound,
            "{file}, rapier: {per_step} allocations a step (at most {bound})"
        );
    }
}
