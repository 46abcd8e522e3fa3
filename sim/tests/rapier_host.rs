//! Many small arenas in one rapier world ([`RapierHost`]): arenas never touch each other, each moves
//! as it would alone, a hosted batch repeats bit for bit, and robots stay inside their walls, off
//! the obstacles and off each other.
use colcos_sim::arena::Obstacles;
use colcos_sim::prelude::*;
use colcos_sim::robot::{
    ArenaPhysics, ColiasParams, MAX_HOSTED_ARENAS, PhysicsBackend, RapierHost,
};

const DT: f32 = 0.02;

fn scenario(file: &str) -> Scenario {
    let path = format!("{}/../scenarios/{file}", env!("CARGO_MANIFEST_DIR"));
    let mut sc = Scenario::from_file(&path).unwrap();
    sc.spec.physics = PhysicsBackend::Rapier;
    sc
}

/// Wheel commands that differ per world, robot and step, and drive robots into walls, obstacles
/// and each other.
fn commands(world: usize, step: usize, robots: usize) -> Vec<WheelCommand> {
    (0..robots)
        .map(|i| {
            let (left, right) = match (step / 40 + i * 7 + world * 13) % 5 {
                0 => (0.3, 0.3),
                1 => (0.3, 0.1),
                2 => (0.1, 0.3),
                3 => (0.35, 0.35),
                _ => (-0.1, 0.2),
            };
            WheelCommand { left, right }
        })
        .collect()
}

/// `worlds` worlds of `sc` stepped in one host; every world's poses after each step.
fn hosted(sc: &Scenario, worlds: usize, steps: usize) -> Vec<Vec<Vec<Pose>>> {
    let mut ws: Vec<World> = (0..worlds)
        .map(|w| World::with_index(sc, w as u64).unwrap())
        .collect();
    let mut host = RapierHost::new(ws[0].arena(), ws[0].obstacles(), worlds);
    for (slot, w) in ws.iter_mut().enumerate() {
        assert!(w.attach_physics(&mut host, slot));
    }
    let mut trace = vec![Vec::new(); worlds];
    for s in 0..steps {
        for (w, world) in ws.iter_mut().enumerate() {
            let cmds: Vec<_> = (commands(w, s, world.robot_count()).into_iter())
                .map(Some)
                .collect();
            world.begin_step_in(&cmds, &mut host);
        }
        host.step(ws[0].dt());
        for (world, trace) in ws.iter_mut().zip(&mut trace) {
            world.finish_step_in(&mut host);
            trace.push(world.poses().to_vec());
        }
    }
    trace
}

#[test]
fn arenas_in_one_host_pass_through_each_other_and_move_as_alone() {
    // Every arena's robot starts on the same spot and drives off in its own direction, into a wall
    // and along it: in one rapier world they would collide at once.
    let size = Vec2::new(1.0, 0.8);
    let params = ColiasParams::default();
    let arenas = MAX_HOSTED_ARENAS;
    let start = |k: usize| {
        [Pose::new(
            0.5,
            0.4,
            k as f32 * std::f32::consts::TAU / arenas as f32,
        )]
    };
    let mut host = RapierHost::new(size, &Obstacles::default(), arenas);
    let mut in_host: Vec<ArenaPhysics> = (0..arenas)
        .map(|k| ArenaPhysics::new(size, &params, &start(k)))
        .collect();
    let mut alone: Vec<ArenaPhysics> = (0..arenas)
        .map(|k| ArenaPhysics::new(size, &params, &start(k)))
        .collect();
    for (k, a) in in_host.iter_mut().enumerate() {
        assert!(a.attach(&mut host, k));
    }
    let v = [(0.3, 0.0)];
    for step in 0..150 {
        for a in &mut in_host {
            a.step_in(&mut host, &v, DT);
        }
        host.step(DT);
        for (k, (a, b)) in in_host.iter_mut().zip(&mut alone).enumerate() {
            a.finish_in(&mut host);
            b.step(&v, DT);
            assert_eq!(a.poses(), b.poses(), "arena {k}, step {step}");
        }
    }
    // They reached their walls.
    let r = params.radius;
    for (k, a) in in_host.iter().enumerate() {
        let p = a.poses()[0].pos;
        let to_wall = p.x.min(p.y).min(size.x - p.x).min(size.y - p.y);
        assert!(
            (to_wall - r).abs() < 1e-3,
            "arena {k}: {to_wall} m from a wall"
        );
    }
}

#[test]
fn a_hosted_batch_repeats_bit_for_bit_and_keeps_robots_apart() {
    let sc = scenario("maze_trail.toml");
    let (worlds, steps) = (16, 1500);
    let a = hosted(&sc, worlds, steps);
    assert!(a == hosted(&sc, worlds, steps), "two runs differ");
    let world = World::new(&sc).unwrap();
    let (size, r) = (world.arena(), world.robot_params().radius);
    let obstacles = world.obstacles();
    let mut worst = 0.0f32;
    for poses in a.iter().flatten() {
        for (i, p) in poses.iter().enumerate() {
            let q = p.pos;
            assert!(q.cmpge(Vec2::splat(r - 1e-4)).all() && q.cmple(size - r + 1e-4).all());
            assert_eq!(obstacles.overlapping(q, r, 0.002), None, "robot {i} at {q}");
            for o in &poses[i + 1..] {
                worst = worst.max(2.0 * r - q.distance(o.pos));
            }
        }
    }
    assert!(worst < 0.002, "robots overlap by {worst} m");
}

#[test]
fn hosted_worlds_move_like_worlds_alone() {
    // A world in a host is stepped by rapier together with others, but rapier keeps each arena's
    // contacts apart: the batch moves as the worlds alone do (bit for bit while no robot touches
    // two things at once, which these scenarios keep to).
    for file in ["case2_alarm.toml", "three_trails.toml"] {
        let sc = scenario(file);
        let (worlds, steps) = (8, 600);
        let batch = hosted(&sc, worlds, steps);
        for (w, trace) in batch.iter().enumerate() {
            let mut world = World::with_index(&sc, w as u64).unwrap();
            for (s, poses) in trace.iter().enumerate() {
                world.step_with_commands(&commands(w, s, world.robot_count()));
                assert_eq!(
                    world.poses(),
                    poses.as_slice(),
                    "{file}: world {w}, step {s}"
                );
            }
        }
    }
}

#[test]
fn arenas_that_do_not_fit_the_host_are_not_attached() {
    let params = ColiasParams::default();
    let size = Vec2::new(1.0, 0.8);
    let mut host = RapierHost::new(size, &Obstacles::default(), 2);
    let poses = [Pose::new(0.5, 0.4, 0.0)];
    let mut other_size = ArenaPhysics::new(Vec2::new(1.2, 0.8), &params, &poses);
    assert!(!other_size.attach(&mut host, 0));
    let mut discs = ArenaPhysics::with_backend(size, &params, &poses, PhysicsBackend::Discs);
    assert!(!discs.attach(&mut host, 0));
    let mut other_obstacles = ArenaPhysics::new(size, &params, &poses);
    let spec = colcos_sim::scenario::parse_spec(
        "duration = 1.0\n[[obstacles]]\nshape = \"box\"\ncentre = [0.2, 0.2]\nsize = [0.05, 0.05]\n",
    )
    .unwrap();
    let boxes = Obstacles::build(&spec.obstacles, size, std::path::Path::new(".")).unwrap();
    other_obstacles.set_obstacles(std::sync::Arc::new(boxes));
    assert!(!other_obstacles.attach(&mut host, 0));
    let mut rapier = ArenaPhysics::new(size, &params, &poses);
    assert!(!rapier.attach(&mut host, 2), "slot 2 of 2");
    assert!(rapier.attach(&mut host, 1));
    // An arena not attached steps alone through step_in.
    let mut alone = ArenaPhysics::new(size, &params, &poses);
    let mut twin = ArenaPhysics::new(size, &params, &poses);
    for _ in 0..50 {
        alone.step_in(&mut host, &[(0.3, 1.0)], DT);
        host.step(DT);
        alone.finish_in(&mut host);
        twin.step(&[(0.3, 1.0)], DT);
    }
    assert_eq!(alone.poses(), twin.poses());
}

#[test]
fn only_arenas_with_a_possible_contact_wake_rapier() {
    let params = ColiasParams::default();
    let size = Vec2::new(1.0, 0.8);
    let mut host = RapierHost::new(size, &Obstacles::default(), 4);
    // Two robots each, far from the walls and each other; arena 3's pair drives head on.
    let mut arenas: Vec<ArenaPhysics> = (0..4)
        .map(|_| {
            ArenaPhysics::new(
                size,
                &params,
                &[
                    Pose::new(0.3, 0.4, 0.0),
                    Pose::new(0.7, 0.4, std::f32::consts::PI),
                ],
            )
        })
        .collect();
    for (k, a) in arenas.iter_mut().enumerate() {
        assert!(a.attach(&mut host, k));
    }
    let mut active = Vec::new();
    for _ in 0..60 {
        for (k, a) in arenas.iter_mut().enumerate() {
            let v = if k == 3 {
                [(0.3, 0.0); 2]
            } else {
                [(0.0, 0.5); 2]
            };
            a.step_in(&mut host, &v, DT);
        }
        host.step(DT);
        for a in &mut arenas {
            a.finish_in(&mut host);
        }
        active.push(host.active_bodies());
    }
    // Turning on the spot, arenas 0-2 never need rapier: their bodies sleep after the first step.
    assert!(active[1..].iter().all(|&n| n <= 2), "{active:?}");
    // Arena 3's robots meet after 0.4 - 0.05 m at 0.6 m/s closing speed: about 29 steps.
    assert_eq!(active[10], 0, "{active:?}");
    assert_eq!(active[40], 2, "{active:?}");
}
