//! Batched throughput with random actions:
//! `cargo run --release -p colcos-env --example throughput -- aggregation 1024 2000 [SCENARIO.toml|-] [rapier|discs]`
//! (`-`: the task's own scenario; the last argument overrides its contact solver).
use colcos_env::{Actions, EnvConfig, ScenarioSource, VecEnv};
use colcos_sim::robot::PhysicsBackend;
use rand::{RngExt, SeedableRng};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let task = args.get(1).map_or("aggregation", String::as_str);
    let num_envs: usize = args.get(2).map_or(Ok(1024), |s| s.parse())?;
    let steps: usize = args.get(3).map_or(Ok(500), |s| s.parse())?;
    let mut cfg = EnvConfig::new(task);
    cfg.num_envs = num_envs;
    if let Some(path) = args.get(4).filter(|p| *p != "-") {
        cfg.scenario = ScenarioSource::File(path.into());
    }
    cfg.physics = match args.get(5).map(String::as_str) {
        None => None,
        Some("rapier") => Some(PhysicsBackend::Rapier),
        Some("discs") => Some(PhysicsBackend::Discs),
        Some(other) => return Err(format!("physics `{other}`: expected rapier or discs").into()),
    };
    cfg.max_cycles = 500;
    let t0 = std::time::Instant::now();
    let mut env = VecEnv::new(&cfg)?;
    env.reset(Some(0), None)?;
    let build = t0.elapsed().as_secs_f64();
    let n = env.spec().num_agents;
    let mut rng = rand::rngs::SmallRng::seed_from_u64(1);
    let mut actions = vec![0.0f32; num_envs * n * 2];
    let t0 = std::time::Instant::now();
    for _ in 0..steps {
        actions
            .iter_mut()
            .for_each(|a| *a = rng.random_range(-1.0..1.0));
        env.step(Actions::Continuous(&actions))?;
    }
    let secs = t0.elapsed().as_secs_f64();
    let agent_steps = (steps * num_envs * n) as f64;
    println!(
        "{task} ({:?}): {num_envs} worlds x {n} agents ({} robots), {steps} steps in {secs:.2} s (build {build:.2} s): {:.0} agent-steps/s, {:.0} world-steps/s",
        env.scenario().spec.physics,
        env.spec().num_robots,
        agent_steps / secs,
        (steps * num_envs) as f64 / secs
    );
    Ok(())
}
