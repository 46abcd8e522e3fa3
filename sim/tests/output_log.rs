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
    let mut log = TrajectoryLog::create(&path, &sc.spec.robots).unwrap();
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

/// Pheromones laid by action get one `lay_<name>` column each: the fraction a robot laid, 0 for
/// robots whose group cannot lay that pheromone; a scenario without deposit actions keeps the plain
/// header (covered above).
#[test]
fn deposit_actions_are_logged_per_pheromone() {
    let disc = Kernel::Disc { radius: 0.01 };
    let sc = ScenarioBuilder::new()
        .duration(1.0)
        .gif_interval(0.0)
        .pheromone(PheromoneSpec::grid("red", [255.0, 0.0, 0.0]))
        .pheromone(PheromoneSpec::grid("green", [0.0, 255.0, 0.0]))
        .robots(
            RobotGroupSpec::new(2, "wander")
                .with_deposit_action("green", disc, 5.0)
                .with_deposit_action("red", disc, 5.0),
        )
        .robots(RobotGroupSpec::new(1, "wander").with_deposit_action("red", disc, 2.0))
        .robots(RobotGroupSpec::new(1, "wander"))
        .build()
        .unwrap();
    let mut world = World::new(&sc).unwrap();
    world.set_deposit_actions(0, [0.25, 0.5]);
    world.set_deposit_actions(1, [1.0, 0.0]);
    world.set_deposit_actions(2, [0.75]);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("trajectory.csv");
    let mut log = TrajectoryLog::create(&path, &sc.spec.robots).unwrap();
    world.step();
    log.record(&world).unwrap();
    drop(log);
    let text = std::fs::read_to_string(&path).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    let plain = colcos_sim::output::trajectory::header();
    assert_eq!(lines[0], format!("{plain},lay_green,lay_red"));
    let tails: Vec<String> = lines[1..]
        .iter()
        .map(|l| l.rsplitn(3, ',').collect::<Vec<_>>()[..2].join(","))
        .collect();
    // rsplitn gives the last column first.
    assert_eq!(
        tails,
        ["0.500,0.250", "0.000,1.000", "0.750,0.000", "0.000,0.000"]
    );
    for (i, l) in lines[1..].iter().enumerate() {
        let row = reference_row(&world, i);
        assert!(
            l.starts_with(&row),
            "robot {i}: {l} does not start with {row}"
        );
    }
}
