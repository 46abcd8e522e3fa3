//! Same scenario and seed give byte-identical logs, whatever the number of threads.
use colcos::run::{RunOptions, run};
use colcos::sim::prelude::*;
use colcos_testkit::scenarios::large_swarm;
use colcos_testkit::threads::on_threads;

/// Enough robots and a large enough grid that the parallel paths (robots and field rows) are taken.
fn scenario() -> Scenario {
    large_swarm()
        .duration(0.6)
        .gif_interval(0.0)
        .build()
        .unwrap()
}

fn run_with_threads(threads: usize) -> (Vec<u8>, Vec<u8>) {
    let sc = scenario();
    let dir = tempfile::tempdir().unwrap();
    on_threads(threads, || {
        run(
            &sc,
            dir.path(),
            &RunOptions {
                progress: false,
                no_gif: true,
                ..Default::default()
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
    let a = scenario();
    let b = a.clone().with_overrides(Some(8), None).unwrap();
    let (wa, wb) = (World::new(&a).unwrap(), World::new(&b).unwrap());
    assert_ne!(wa.poses()[0], wb.poses()[0]);
}
