//! An arena with 200 obstacles and 1,000 robots: the share of a world step that the bumper pass takes
//! (every robot's three IR rays against walls, robots and obstacles), for both solvers. The bumper
//! pass is timed on its own over the world's poses as the sense stage runs it (neighbour index
//! rebuilt, rays cast in parallel over the robots), beside the same pass without the obstacles and
//! the median whole step. Target: the bumper pass at most 20 % of the step.
//!
//! cargo bench -p colcos-sim --bench obstacle_bumpers
use colcos_sim::arena::{ObstacleKind, ObstacleShape, ObstacleSpec, Obstacles};
use colcos_sim::robot::PhysicsBackend;
use colcos_sim::scenario::Scenario;
use colcos_sim::sensors::{BumperParams, BumperRays, NeighbourIndex};
use colcos_sim::world::World;
use colcos_testkit::scenarios::trail_followers;
use glam::Vec2;
use rayon::prelude::*;
use std::time::Instant;

const ROBOTS: usize = 1_000;
/// Ten times the 65-inch screen's area: 100 robots per screen, as in the paper's densest runs.
const ARENA: [f32; 2] = [4.55, 2.56];

/// An obstacle of `shape` with none of its keys set yet.
fn obstacle(shape: ObstacleShape) -> ObstacleSpec {
    ObstacleSpec {
        shape,
        kind: ObstacleKind::Physical,
        colour: None,
        centre: None,
        size: None,
        angle: None,
        radius: None,
        points: None,
        thickness: None,
        image: None,
        channel: None,
        threshold: None,
        pixels: None,
    }
}

/// 200 obstacles on a jittered 20 x 10 grid, cycling through boxes, discs, walls and concave polygons.
fn scenario(physics: PhysicsBackend) -> Scenario {
    let (w, h) = (ARENA[0], ARENA[1]);
    let obstacles = (0..200)
        .map(|k| {
            let (i, j) = (k % 20, k / 20);
            let jitter = ((k * 37 % 11) as f32 - 5.0) * 0.006;
            let c = Vec2::new(
                (i as f32 + 0.5) * w / 20.0 + jitter,
                (j as f32 + 0.5) * h / 10.0 - jitter,
            );
            match k % 4 {
                0 => ObstacleSpec {
                    centre: Some([c.x, c.y]),
                    size: Some([0.08, 0.05]),
                    angle: Some((k * 17 % 90) as f32),
                    ..obstacle(ObstacleShape::Box)
                },
                1 => ObstacleSpec {
                    centre: Some([c.x, c.y]),
                    radius: Some(0.04),
                    ..obstacle(ObstacleShape::Disc)
                },
                2 => ObstacleSpec {
                    points: Some(vec![
                        [c.x - 0.06, c.y],
                        [c.x + 0.06, c.y],
                        [c.x + 0.06, c.y + 0.06],
                    ]),
                    thickness: Some(0.01),
                    ..obstacle(ObstacleShape::Wall)
                },
                _ => ObstacleSpec {
                    points: Some(vec![
                        [c.x - 0.05, c.y - 0.05],
                        [c.x + 0.05, c.y - 0.05],
                        [c.x + 0.05, c.y - 0.02],
                        [c.x - 0.02, c.y - 0.02],
                        [c.x - 0.02, c.y + 0.05],
                        [c.x - 0.05, c.y + 0.05],
                    ]),
                    ..obstacle(ObstacleShape::Polygon)
                },
            }
        })
        .collect();
    trail_followers(ROBOTS)
        .physics(physics)
        .screen([4550, 2560], ARENA)
        .cell(0.01)
        .with(|s| s.obstacles = obstacles)
        .build()
        .expect("bench scenario is valid")
}

fn median(mut xs: Vec<f64>) -> f64 {
    xs.sort_by(f64::total_cmp);
    xs[xs.len() / 2]
}

/// One bumper pass over `world`'s robots as the sense stage runs it, s.
fn bumper_pass(
    world: &World,
    index: &mut NeighbourIndex,
    obstacles: &Obstacles,
    out: &mut Vec<[f32; 3]>,
) -> f64 {
    let params = BumperParams::default();
    let rays = BumperRays::new(&params);
    let r = world.robot_params().radius;
    let arena = world.arena();
    let t = Instant::now();
    let positions: Vec<Vec2> = world.poses().iter().map(|p| p.pos).collect();
    index.rebuild(arena, NeighbourIndex::cell_for(r, &params), &positions);
    let (index, poses) = (&*index, world.poses());
    (0..poses.len())
        .into_par_iter()
        .map(|i| index.bumpers_facing(i, poses, poses[i].forward(), r, arena, &rays, obstacles))
        .collect_into_vec(out);
    t.elapsed().as_secs_f64()
}

fn main() {
    println!(
        "{ROBOTS} robots, 200 obstacles ({} parry2d parts), arena {} x {} m, {} threads",
        scenario(PhysicsBackend::Discs)
            .obstacles()
            .unwrap()
            .parts()
            .len(),
        ARENA[0],
        ARENA[1],
        rayon::current_num_threads()
    );
    for (physics, backend) in [
        ("rapier", PhysicsBackend::Rapier),
        ("discs", PhysicsBackend::Discs),
    ] {
        let mut world = World::new(&scenario(backend)).unwrap();
        for _ in 0..20 {
            world.step();
        }
        let (mut steps, mut with, mut without) = (Vec::new(), Vec::new(), Vec::new());
        let mut index = NeighbourIndex::default();
        let mut out = Vec::new();
        let none = Obstacles::default();
        let mut hits = 0;
        for _ in 0..60 {
            let t = Instant::now();
            world.step();
            steps.push(t.elapsed().as_secs_f64());
            with.push(bumper_pass(&world, &mut index, world.obstacles(), &mut out));
            hits += out.iter().filter(|b| b.iter().any(|&x| x > 0.0)).count();
            without.push(bumper_pass(&world, &mut index, &none, &mut out));
        }
        let (step, with, without) = (median(steps), median(with), median(without));
        let share = with / step;
        println!(
            "{physics}: median step {:.2} ms; bumper pass {:.3} ms with obstacles ({:.3} ms without, {:.2}x); \
             bumper share of the step {:.1} % (target <= 20 %: {}); {:.0} robots per step see something",
            step * 1e3,
            with * 1e3,
            without * 1e3,
            with / without,
            share * 100.0,
            if share <= 0.2 { "met" } else { "NOT met" },
            hits as f64 / 60.0
        );
    }
}
