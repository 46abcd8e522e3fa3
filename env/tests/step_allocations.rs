//! A batched step allocates nothing of its own between episode ends: every output buffer, scratch
//! buffer and world is built once. What remains is buffers growing to a new high-water mark now and
//! then (more pheromone sources, a larger pile of robots) and, with rapier, its pipeline's few blocks
//! in a step with contacts.
use colcos_env::{Actions, EnvConfig, VecEnv};
use colcos_sim::robot::PhysicsBackend;
use colcos_testkit::alloc::{Counting, allocations, assert_installed};

#[global_allocator]
static ALLOCATOR: Counting = Counting;

/// Allocations per world and step over 100 steps of 64 worlds, after 100 steps to warm up; episodes
/// are longer than the 200 steps, so no world is rebuilt.
fn allocations_per_world_step(task: &str, physics: PhysicsBackend) -> f64 {
    let mut cfg = EnvConfig::new(task);
    cfg.num_envs = 64;
    cfg.num_threads = Some(2);
    cfg.max_cycles = 1_000;
    cfg.physics = Some(physics);
    let mut env = VecEnv::new(&cfg).unwrap();
    env.reset(Some(3), None).unwrap();
    let n = env.spec().num_agents;
    // Fixed actions that turn and drive, so robots meet walls and each other.
    let actions: Vec<f32> = (0..64 * n * 2)
        .map(|k| [0.9, 0.4, -0.3, 1.0, 0.7, 0.7][k % 6])
        .collect();
    for _ in 0..100 {
        env.step(Actions::Continuous(&actions)).unwrap();
    }
    let before = allocations();
    for _ in 0..100 {
        env.step(Actions::Continuous(&actions)).unwrap();
    }
    (allocations() - before) as f64 / (100.0 * 64.0)
}

/// One test, as the counter counts every thread's allocations. Measured: discs 0.001-0.007 a world
/// and step, rapier 0.4-1.3.
#[test]
fn a_batched_step_allocates_nothing_of_its_own() {
    assert_installed();
    for task in ["aggregation", "foraging", "trail"] {
        let discs = allocations_per_world_step(task, PhysicsBackend::Discs);
        assert!(
            discs < 0.05,
            "{task}, discs: {discs} allocations a world and step"
        );
        let rapier = allocations_per_world_step(task, PhysicsBackend::Rapier);
        assert!(
            rapier < 4.0,
            "{task}, rapier: {rapier} allocations a world and step"
        );
    }
}
