//! The vector env's field backends side by side: agent-steps per second of task `trail` (4 agents a
//! world, one scripted red trail each, a static blue loop) on the CPU backend and with every world's
//! fields in the resident GPU batch (`backend = "gpu"`), in one run, with their ratio; and what
//! `auto` picks at each size. Plain timing, no criterion (a GPU step can take 100 ms on a software
//! driver, whose figures say nothing about a hardware GPU).
//!
//! `cargo bench -p colcos-env --features gpu --bench gpu_vec_env`, with
//! * `COLCOS_BENCH_WORLDS`: batch sizes, comma-separated (default `1024,4096`);
//! * `COLCOS_BENCH_THREADS`: the CPU backend's thread counts, comma-separated, `all` for every core
//!   (default `all`); the GPU path runs on every core;
//! * `COLCOS_BENCH_STEPS`: timed steps per figure (default 30, after 3 untimed ones);
//! * `COLCOS_BENCH_TASK`: the task (default `trail`).
use colcos_env::{Actions, EnvConfig, VecEnv};
use colcos_sim::field::BackendChoice;
use std::time::Instant;

fn var(name: &str, default: &str) -> String {
    std::env::var(name).unwrap_or_else(|_| default.to_string())
}

fn list(name: &str, default: &str) -> Vec<String> {
    var(name, default)
        .split(',')
        .map(|s| s.trim().to_string())
        .filter(|s| !s.is_empty())
        .collect()
}

/// Agent-steps per second of `steps` steps (after 3 untimed), or the error that stopped the env.
fn rate(
    task: &str,
    worlds: usize,
    threads: Option<usize>,
    backend: BackendChoice,
    steps: usize,
) -> Result<(f64, String), String> {
    let mut cfg = EnvConfig::new(task);
    cfg.num_envs = worlds;
    cfg.num_threads = threads;
    cfg.backend = Some(backend);
    cfg.seed = 1;
    let mut env = VecEnv::new(&cfg).map_err(|e| e.to_string())?;
    env.reset(None, None).map_err(|e| e.to_string())?;
    let s = env.spec().clone();
    let width = s.action.flat_len();
    let pool: Vec<Vec<f32>> = (0..8)
        .map(|p| {
            (0..s.num_envs * s.num_agents * width)
                .map(|k| (((k * 37 + p * 101) % 23) as f32 / 11.0) - 1.0)
                .collect()
        })
        .collect();
    for p in pool.iter().take(3) {
        env.step(Actions::Continuous(p))
            .map_err(|e| e.to_string())?;
    }
    let before = env.gpu_stage_seconds();
    let t0 = Instant::now();
    for k in 0..steps {
        env.step(Actions::Continuous(&pool[k % 8]))
            .map_err(|e| e.to_string())?;
    }
    let secs = t0.elapsed().as_secs_f64();
    let mut how = env.backend().describe().to_string();
    if let (Some(a), Some(b)) = (before, env.gpu_stage_seconds()) {
        let parts: Vec<String> = (colcos_env::GPU_STAGE_PARTS.iter().enumerate())
            .map(|(k, name)| format!("{name} {:.2}", (b[k] - a[k]) * 1e3 / steps as f64))
            .collect();
        how.push_str(&format!("; ms a step: {}", parts.join(", ")));
    }
    Ok(((worlds * s.num_agents * steps) as f64 / secs, how))
}

fn main() {
    // `cargo bench` passes --bench; `cargo test --benches` passes nothing useful: run only under bench.
    if !std::env::args().any(|a| a == "--bench") {
        return;
    }
    let task = var("COLCOS_BENCH_TASK", "trail");
    let steps: usize = var("COLCOS_BENCH_STEPS", "30").parse().unwrap_or(30);
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let threads: Vec<Option<usize>> = list("COLCOS_BENCH_THREADS", "all")
        .iter()
        .map(|t| if t == "all" { None } else { t.parse().ok() })
        .collect();
    println!("task {task}, {steps} timed steps a figure, {cores} cores");
    for worlds in list("COLCOS_BENCH_WORLDS", "1024,4096") {
        let Ok(worlds) = worlds.parse::<usize>() else {
            println!("COLCOS_BENCH_WORLDS: {worlds:?} is not a number of worlds");
            continue;
        };
        let mut cpu = Vec::new();
        for &t in &threads {
            let label = t.map_or(format!("all {cores} threads"), |t| format!("{t} thread(s)"));
            match rate(&task, worlds, t, BackendChoice::Cpu, steps) {
                Ok((r, _)) => {
                    println!(
                        "{worlds:>6} worlds  CPU backend, {label:<16} {r:>12.0} agent-steps/s"
                    );
                    cpu.push((label, r));
                }
                Err(e) => println!("{worlds:>6} worlds  CPU backend, {label}: {e}"),
            }
        }
        match rate(&task, worlds, None, BackendChoice::Gpu, steps) {
            Ok((r, how)) => {
                println!(
                    "{worlds:>6} worlds  GPU batch, all threads      {r:>12.0} agent-steps/s  [{how}]"
                );
                for (label, c) in &cpu {
                    println!(
                        "{worlds:>6} worlds  GPU batch / CPU backend ({label}): {:.2}x",
                        r / c
                    );
                }
            }
            Err(e) => println!("{worlds:>6} worlds  GPU batch: {e}"),
        }
        match rate(&task, worlds, None, BackendChoice::Auto, steps.min(5)) {
            Ok((_, how)) => println!("{worlds:>6} worlds  auto picks: {how}"),
            Err(e) => println!("{worlds:>6} worlds  auto: {e}"),
        }
    }
}
