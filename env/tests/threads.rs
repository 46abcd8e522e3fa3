//! The batched environment gives the same observations, rewards, flags and state whatever the
//! number of worker threads, for both contact solvers: worlds stepped on different threads (which
//! share a thread's rapier pipeline with different neighbours), 31 worlds to a shared rapier host in
//! 32 hosts, and rebuilt by autoreset.
use colcos_env::{Actions, EnvConfig, VecEnv};
use colcos_sim::robot::PhysicsBackend;

fn run(task: &str, maze: bool, physics: PhysicsBackend, threads: usize) -> Vec<u32> {
    let mut cfg = EnvConfig::new(task);
    cfg.num_envs = 992;
    cfg.max_cycles = 70;
    cfg.seed = 3;
    cfg.num_threads = Some(threads);
    cfg.physics = Some(physics);
    if maze {
        cfg.params = serde_json::json!({ "maze": true });
    }
    let mut env = VecEnv::new(&cfg).unwrap();
    env.reset(Some(3), None).unwrap();
    let len = env.spec().num_envs * env.spec().num_agents * 2;
    let mut out = Vec::new();
    for t in 0..80 {
        // Full-speed pushes into each other and the walls, changing every few steps.
        let a: Vec<f32> = (0..len)
            .map(|k| ((k * 13 + (t / 7) * 5) as f32 * 0.61).sin().signum())
            .collect();
        env.step(Actions::Continuous(&a)).unwrap();
        out.extend(env.outputs().obs().iter().map(|x| x.to_bits()));
        out.extend(env.outputs().rewards().iter().map(|x| x.to_bits()));
        out.extend(env.outputs().state().iter().map(|x| x.to_bits()));
        out.extend(env.outputs().terminated().iter().map(|&x| x as u32));
    }
    out
}

#[test]
fn thread_count_does_not_change_the_outputs() {
    for (task, maze) in [("aggregation", false), ("trail", true)] {
        for physics in [PhysicsBackend::Rapier, PhysicsBackend::Discs] {
            let one = run(task, maze, physics, 1);
            for threads in [2, 4] {
                assert!(
                    one == run(task, maze, physics, threads),
                    "{task} (maze {maze}), {physics:?}: 1 and {threads} threads differ"
                );
            }
        }
    }
}
