//! The trajectory log: rows as `{:.N}` formats them, in robot order, for a swarm large enough to be
//! formatted in parallel chunks.
use colcos_sim::field::Kernel;
use colcos_sim::output::TrajectoryLog;
use colcos_sim::prelude::*;
use colcos_sim::scenario::{PheromoneSpec, RobotGroupSpec, ScenarioBuilder};
use std::fmt::Write as _;

/// One row the obvious way (the log's format written with `write!`).
fn reference_row(world: &World, i: usize) -> String {
    let (p, t, o) = (
        &world.poses()[i],
        &world.tracked()[i],
        &world.observations()[i],
    );
    let cmd = world.robots()[i].command;
    let mut l = format!(
        "{},{:.2},{},{},{:.5},{:.5},{:.4},{:.5},{:.5},{:.4},{},{:.4},{:.4}",
        world.tick(),
        world.time(),
        i,
        world.role(i),
        p.pos.x,
        p.pos.y,
        p.heading,
        t.pose.pos.x,
        t.pose.pos.y,
        t.pose.heading,
        t.seen as u8,
        cmd.left,
        cmd.right
    );
    for c in o.counts.iter().flatten() {
        let _ = write!(l, ",{c}");
    }
    for b in &o.bumpers {
        let _ = write!(l, ",{b:.3}");
    }
    l
}

#[test]
fn a_large_swarm_logs_every_row_in_order_as_std_formats_it() {
    let sc = ScenarioBuilder::new()
        .duration(1.0)
        .screen([3840, 2160], [3.2, 1.8])
        .cell(0.01)
        .gif_interval(0.0)
        .pheromone(PheromoneSpec::grid("red", [255.0, 0.0, 0.0]))
        .robots(
            RobotGroupSpec::new(1300, "wander")
                .with_role("walker")
                .with_deposit("red", Kernel::Disc { radius: 0.01 }, 5.0),
        )
        .build()
        .unwrap();
    let mut world = World::new(&sc).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("trajectory.csv");
    let mut log = TrajectoryLog::create(&path).unwrap();
    let mut want = vec![colcos_sim::output::trajectory::header()];
    for _ in 0..3 {
        world.step();
        log.record(&world).unwrap();
        want.extend((0..world.robot_count()).map(|i| reference_row(&world, i)));
    }
    drop(log);
    let got = std::fs::read_to_string(&path).unwrap();
    let got: Vec<&str> = got.lines().collect();
    assert_eq!(got.len(), 1 + 3 * 1300);
    for (k, (g, w)) in got.iter().zip(&want).enumerate() {
        assert_eq!(g, w, "line {k}");
    }
}
