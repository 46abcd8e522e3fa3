//! The hand-written policies of `colony`, `coverage` and `alarm` against uniform random actions, on
//! the same seeded episodes, and each policy with its deposit rates forced to 0 (what its
//! pheromone is worth to it): the table of docs/tasks.md ("Baselines").
//!
//!     cargo run --release -p colcos-env --example task_baselines -- [worlds] [seeds]
//!
//! Each seed resets `worlds` worlds with that seed and runs one whole episode in each; a row gives
//! the mean episode return of one agent (the tasks' rewards are team rewards, the same for every
//! agent) over all of them, with the standard deviation across episodes.
use colcos_env::baseline::BaselinePolicy;
use colcos_env::{Actions, EnvConfig, VecEnv, policy};
use rand::{RngExt, SeedableRng, rngs::SmallRng};

/// Who acts.
#[derive(Clone, Copy, PartialEq)]
enum Who {
    Hand,
    /// The hand-written policy, laying nothing.
    Silent,
    Random,
}

/// Mean episode return per agent of every world's first episode after `reset(seed)`.
fn returns(task: &str, worlds: usize, seed: u64, who: Who) -> Vec<f64> {
    let mut cfg = EnvConfig::new(task);
    cfg.num_envs = worlds;
    cfg.seed = seed;
    let mut env = VecEnv::new(&cfg).unwrap();
    env.reset(Some(seed), None).unwrap();
    let (n, width, steps) = (
        env.spec().num_agents,
        env.action_decoder().width(),
        env.spec().max_cycles,
    );
    let name = policy::for_task(task).unwrap();
    let mut baseline = BaselinePolicy::new(&env, name, &serde_json::Value::Null, seed).unwrap();
    let mut rng = SmallRng::seed_from_u64(seed ^ 0x5eed);
    let mut a = vec![0.0f32; worlds * n * width];
    let mut total = vec![0.0f64; worlds];
    for _ in 0..steps {
        if who != Who::Random {
            baseline.act(&env, &mut a).unwrap();
            if who == Who::Silent {
                (a.iter_mut().enumerate())
                    .filter(|(j, _)| j % width >= 2)
                    .for_each(|(_, v)| *v = 0.0);
            }
        } else {
            for (j, v) in a.iter_mut().enumerate() {
                *v = if j % width < 2 {
                    rng.random_range(-1.0..1.0)
                } else {
                    rng.random_range(0.0..1.0)
                };
            }
        }
        env.step(Actions::Continuous(&a)).unwrap();
        for (w, t) in total.iter_mut().enumerate() {
            *t += env.outputs().rewards()[w * n..(w + 1) * n]
                .iter()
                .sum::<f32>() as f64
                / n as f64;
        }
    }
    total
}

fn main() {
    let args: Vec<usize> = std::env::args()
        .skip(1)
        .map(|a| a.parse().expect("worlds and seeds are integers"))
        .collect();
    let (worlds, seeds) = (
        args.first().copied().unwrap_or(16),
        args.get(1).copied().unwrap_or(3),
    );
    println!("| task | policy | return (mean ± sd) | episodes |");
    println!("| --- | --- | --- | --- |");
    for task in ["colony", "coverage", "alarm"] {
        for who in [Who::Hand, Who::Silent, Who::Random] {
            let all: Vec<f64> = (0..seeds as u64)
                .flat_map(|s| returns(task, worlds, s, who))
                .collect();
            let mean = all.iter().sum::<f64>() / all.len() as f64;
            let var = all.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / all.len() as f64;
            let name = policy::for_task(task).unwrap();
            let who = match who {
                Who::Hand => name.to_string(),
                Who::Silent => format!("{name}, rates forced to 0"),
                Who::Random => "random".into(),
            };
            println!(
                "| `{task}` | {who} | {mean:.2} ± {:.2} | {} |",
                var.sqrt(),
                all.len()
            );
        }
    }
}
