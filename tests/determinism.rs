//! Same scenario and seed give byte-identical logs, whatever the number of threads.
use colcos::run::{RunOptions, run};
use colcos::sim::prelude::*;

/// Enough robots and a large enough grid that the parallel paths (robots and field rows) are taken.
const SCENARIO: &str = r#"
duration = 0.6
seed = 7
[screen]
resolution = [3840, 2160]
size = [2.4, 1.35]
[field]
cell = 0.003
[output]
gif_interval = 0
[[pheromones]]
name = "red"
colour = [255, 0, 0]
evaporation = 5.0
diffusion = 1e-5
[[pheromones]]
name = "blue"
colour = [0, 0, 255]
evaporation = 5.0
diffusion = 1e-6
maps = [{ polyline = [[0.2, 0.2], [2.2, 1.1]], width = 0.05, rate = 0.2 }]
[[robots]]
count = 200
behaviour = "follow"
params = { channel = "b" }
deposits = [{ pheromone = "red", kernel = { shape = "cone", radius = 0.01 }, rate = 5.0 }]
[[robots]]
count = 150
behaviour = "avoid"
deposits = [{ pheromone = "blue", kernel = { shape = "disc", radius = 0.01 }, rate = 5.0 }]
"#;

fn run_with_threads(threads: usize) -> (Vec<u8>, Vec<u8>) {
    let sc = Scenario::from_toml_str(SCENARIO, ".").unwrap();
    let dir = tempfile::tempdir().unwrap();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(|| {
        run(
            &sc,
            dir.path(),
            &RunOptions {
                progress: false,
                no_gif: true,
            },
        )
    })
    .unwrap();
    let log = std::fs::read(dir.path().join("trajectory.csv")).unwrap();
    let field = std::fs::read(dir.path().join("fields/red.npy")).unwrap();
    (log, field)
}

#[test]
fn logs_are_identical_across_thread_counts() {
    let (one, f1) = run_with_threads(1);
    assert!(one.len() > 10_000, "log too short: {} bytes", one.len());
    for n in [2, 4] {
        let (log, field) = run_with_threads(n);
        assert!(log == one, "trajectory log differs with {n} threads");
        assert!(field == f1, "final field differs with {n} threads");
    }
}

#[test]
fn a_different_seed_gives_a_different_run() {
    let a = Scenario::from_toml_str(SCENARIO, ".").unwrap();
    let b = a.clone().with_overrides(Some(8), None).unwrap();
    let (wa, wb) = (World::new(&a).unwrap(), World::new(&b).unwrap());
    assert_ne!(wa.poses()[0], wb.poses()[0]);
}
