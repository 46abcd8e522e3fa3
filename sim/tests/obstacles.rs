//! Obstacles: bumper rays against parry2d shapes at known poses, contacts in both solvers, placement
//! and validation errors naming the key.
use colcos_sim::arena::{Obstacles, merge_runs};
use colcos_sim::robot::{ArenaPhysics, ColiasParams, PhysicsBackend, Pose};
use colcos_sim::scenario::Scenario;
use colcos_sim::sensors::{BumperParams, BumperRays, NeighbourIndex};
use colcos_sim::world::World;
use colcos_testkit::parsing::assert_all_refused;
use colcos_testkit::threads::on_threads;
use glam::Vec2;
use rand::{RngExt, SeedableRng};
use std::path::Path;
use std::sync::Arc;

const R: f32 = 0.02;
const ARENA: Vec2 = Vec2::new(1.0, 1.0);
const BACKENDS: [PhysicsBackend; 2] = [PhysicsBackend::Rapier, PhysicsBackend::Discs];

fn obstacles(toml_entries: &str) -> Obstacles {
    let text = format!("duration = 1.0\n{toml_entries}");
    let spec = colcos_sim::scenario::parse_spec(&text).unwrap();
    Obstacles::build(&spec.obstacles, ARENA, Path::new(".")).unwrap()
}

/// The three readings of one robot at `pose`, alone in the arena with `obs`.
fn bumpers(obs: &Obstacles, pose: Pose) -> [f32; 3] {
    let params = BumperParams::default();
    let mut index = NeighbourIndex::default();
    index.rebuild(ARENA, 0.1, &[pose.pos]);
    let rays = BumperRays::new(&params);
    index.bumpers_facing(0, &[pose], pose.forward(), R, ARENA, &rays, obs)
}

/// One obstacle of every shape: a rotated box, a disc, a concave polygon and a bent wall.
const EVERY_SHAPE: &str = r#"
[[obstacles]]
shape = "box"
centre = [0.3, 0.3]
size = [0.15, 0.1]
angle = 30
[[obstacles]]
shape = "disc"
centre = [0.7, 0.3]
radius = 0.08
[[obstacles]]
shape = "polygon"
points = [[0.2, 0.6], [0.45, 0.6], [0.45, 0.85], [0.35, 0.85], [0.35, 0.7], [0.2, 0.7]]
[[obstacles]]
shape = "wall"
points = [[0.6, 0.55], [0.8, 0.75], [0.9, 0.6]]
thickness = 0.01
"#;

/// `poses` in the physics of `backend` among `obs`.
fn physics_among(obs: &Arc<Obstacles>, poses: &[Pose], backend: PhysicsBackend) -> ArenaPhysics {
    let mut phys = ArenaPhysics::with_backend(ARENA, &ColiasParams::default(), poses, backend);
    phys.set_obstacles(obs.clone());
    phys
}

/// Drives every robot of `phys` for `steps` steps of 20 ms, each with a new random (forward m/s,
/// turn rad/s) from `forward` and `turn` every 25 steps; `check(step, poses)` after every step.
fn drive_randomly(
    phys: &mut ArenaPhysics,
    seed: u64,
    steps: usize,
    (forward, turn): (std::ops::Range<f32>, std::ops::Range<f32>),
    mut check: impl FnMut(usize, &[Pose]),
) {
    let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
    let mut v = vec![(0.0, 0.0); phys.poses().len()];
    for step in 0..steps {
        if step % 25 == 0 {
            for x in v.iter_mut() {
                *x = (
                    rng.random_range(forward.clone()),
                    rng.random_range(turn.clone()),
                );
            }
        }
        phys.step(&v, 0.02);
        check(step, phys.poses());
    }
}

fn close(a: f32, b: f32, tol: f32) -> bool {
    (a - b).abs() <= tol
}

#[test]
fn bumper_distance_to_a_wall_face() {
    // A wall along x = 0.535 (0.01 thick: face at 0.53); the robot's rim at 0.52: 1 cm to the face.
    let obs = obstacles(
        "[[obstacles]]\nshape = \"wall\"\npoints = [[0.535, 0.2], [0.535, 0.8]]\nthickness = 0.01\n",
    );
    let r = bumpers(&obs, Pose::new(0.5, 0.5, 0.0));
    assert!(close(r[1], 1.0 - 0.01 / 0.02, 1e-4), "front {r:?}");
    // The diagonal rays start at the rim (0.5 + 0.02 cos 45) and meet the face after
    // (0.53 - 0.51414) / cos 45 = 0.02243 m: beyond the 2 cm range.
    assert_eq!(r[0], 0.0, "{r:?}");
    assert_eq!(r[2], 0.0, "{r:?}");
    // Turned towards it by 45 degrees, the right ray is the straight one.
    let r = bumpers(&obs, Pose::new(0.5, 0.5, std::f32::consts::FRAC_PI_4));
    assert!(close(r[2], 0.5, 1e-4), "right {r:?}");
}

#[test]
fn bumper_distance_to_a_box_corner_and_a_disc() {
    // A box rotated 45 degrees whose left corner sits at (0.53, 0.5): the front ray meets it 1 cm
    // from the rim.
    let half = 0.05;
    let cx = 0.53 + half * std::f32::consts::SQRT_2;
    let obs = obstacles(&format!(
        "[[obstacles]]\nshape = \"box\"\ncentre = [{cx}, 0.5]\nsize = [{s}, {s}]\nangle = 45\n",
        s = 2.0 * half
    ));
    let r = bumpers(&obs, Pose::new(0.5, 0.5, 0.0));
    assert!(close(r[1], 0.5, 1e-3), "corner {r:?}");
    // A disc of radius 0.05 centred 0.085 away along the front-left ray: rim 0.02 + face 0.015.
    let d = Vec2::from_angle(std::f32::consts::FRAC_PI_4);
    let c = Vec2::new(0.5, 0.5) + 0.085 * d;
    let obs = obstacles(&format!(
        "[[obstacles]]\nshape = \"disc\"\ncentre = [{}, {}]\nradius = 0.05\n",
        c.x, c.y
    ));
    let r = bumpers(&obs, Pose::new(0.5, 0.5, 0.0));
    assert!(close(r[0], 1.0 - 0.015 / 0.02, 1e-3), "disc {r:?}");
    assert_eq!(r[2], 0.0, "{r:?}");
}

#[test]
fn a_robot_driven_into_a_box_stops_at_its_face() {
    let obs = Arc::new(obstacles(
        "[[obstacles]]\nshape = \"box\"\ncentre = [0.6, 0.5]\nsize = [0.2, 0.3]\n",
    ));
    for backend in BACKENDS {
        let mut phys = physics_among(&obs, &[Pose::new(0.3, 0.5, 0.0)], backend);
        for _ in 0..250 {
            phys.step(&[(0.1, 0.0)], 0.02);
        }
        let x = phys.poses()[0].pos.x;
        // The face is at x = 0.5: the centre stops one radius before it, within 1 mm.
        assert!(close(x, 0.5 - R, 1e-3), "{backend:?}: x = {x}");
    }
}

/// Largest overlap of any robot disc with any obstacle, m.
fn worst_overlap(obs: &Obstacles, poses: &[Pose]) -> f32 {
    let mut worst = 0.0f32;
    for p in poses {
        for slack in [0.0005, 0.001, 0.002, 0.005, 0.01, R] {
            if obs.overlapping(p.pos, R, slack).is_none() {
                break;
            }
            worst = worst.max(slack);
        }
    }
    worst
}

#[test]
fn robots_never_end_inside_obstacles_after_10000_random_steps() {
    let obs = Arc::new(obstacles(EVERY_SHAPE));
    for backend in BACKENDS {
        // Robots on a grid, off the obstacles.
        let mut poses = Vec::new();
        for k in 0..100 {
            let q = Vec2::new(0.05 + (k % 10) as f32 * 0.1, 0.05 + (k / 10) as f32 * 0.1);
            if obs.overlapping(q, R + 0.002, 0.0).is_none() {
                poses.push(Pose::new(q.x, q.y, k as f32));
            }
        }
        // rapier's contacts are springs: a robot pushed by others may press a little in.
        let tol = if backend == PhysicsBackend::Rapier {
            0.002
        } else {
            0.0005
        };
        let mut phys = physics_among(&obs, &poses, backend);
        drive_randomly(
            &mut phys,
            7,
            10_000,
            (-0.1..0.35, -4.0..4.0),
            |step, poses| {
                let w = worst_overlap(&obs, poses);
                assert!(w <= tol, "{backend:?} step {step}: overlap {w} m");
            },
        );
    }
}

#[test]
fn mask_runs_cover_exactly_the_solid_pixels() {
    let pattern = ["..##..", "..##..", "######", "#....#"];
    let solid = |x: u32, y: u32| pattern[y as usize].as_bytes()[x as usize] == b'#';
    let rects = merge_runs(6, 4, solid);
    let mut covered = [[0u8; 6]; 4];
    for (x0, y0, x1, y1) in &rects {
        for row in covered.iter_mut().take(*y1 as usize).skip(*y0 as usize) {
            for c in row.iter_mut().take(*x1 as usize).skip(*x0 as usize) {
                *c += 1;
            }
        }
    }
    for (y, row) in covered.iter().enumerate() {
        for (x, &c) in row.iter().enumerate() {
            assert_eq!(c, solid(x as u32, y as u32) as u8, "pixel ({x}, {y})");
        }
    }
    // The two-row stem merges into one box.
    assert_eq!(rects.len(), 4, "{rects:?}");
}

const BASE: &str = r#"
duration = 1.0
[screen]
size = [1.0, 1.0]
resolution = [200, 200]
[[robots]]
count = 20
behaviour = "avoid"
"#;

fn err(extra: &str) -> String {
    match Scenario::from_toml_str(&format!("{BASE}{extra}"), ".") {
        Ok(_) => panic!("accepted:\n{extra}"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn bad_obstacles_are_refused_naming_the_key() {
    let obstacle = |body: &str| format!("{BASE}[[obstacles]]\n{body}\n");
    assert_all_refused(&[
        (
            obstacle("shape = \"box\"\ncentre = [0.95, 0.5]\nsize = [0.2, 0.1]"),
            &["obstacles[0].centre", "outside the arena"],
        ),
        (
            obstacle("shape = \"box\"\ncentre = [0.5, 0.5]\nsize = [0.0, 0.1]"),
            &["obstacles[0].size", "[0.0, 0.1]"],
        ),
        (
            obstacle("shape = \"polygon\"\npoints = [[0.1, 0.1], [0.2, 0.2], [0.3, 0.3]]"),
            &["obstacles[0].points", "no area"],
        ),
        (
            obstacle(
                "shape = \"polygon\"\npoints = [[0.1, 0.1], [0.3, 0.3], [0.3, 0.1], [0.1, 0.3]]",
            ),
            &["obstacles[0].points", "cross"],
        ),
        (
            obstacle("shape = \"disc\"\ncentre = [0.5, 0.5]"),
            &["obstacles[0].radius", "missing"],
        ),
        (
            obstacle("shape = \"disc\"\ncentre = [0.5, 0.5]\nradius = 0.1\nsize = [1, 1]"),
            &["obstacles[0].size"],
        ),
        (
            obstacle("shape = \"mask\"\nimage = \"no_such_mask.png\""),
            &["obstacles[0].image", "no_such_mask.png"],
        ),
        (
            obstacle("shape = \"wall\"\npoints = [[0.1, 0.1], [0.1, 0.1]]\nthickness = 0.01"),
            &["obstacles[0].points[1]"],
        ),
    ]);
}

#[test]
fn a_mask_of_the_wrong_size_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let img = image::GrayImage::from_fn(20, 10, |x, _| image::Luma([if x < 5 { 255 } else { 0 }]));
    img.save(dir.path().join("m.png")).unwrap();
    let text =
        format!("{BASE}[[obstacles]]\nshape = \"mask\"\nimage = \"m.png\"\npixels = [10, 10]\n");
    let e = Scenario::from_toml_str(&text, dir.path())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("obstacles[0].pixels") && e.contains("20 x 10"),
        "{e}"
    );
    // The right size loads: the left quarter of the arena is solid, no robot starts there.
    let text = text.replace("[10, 10]", "[20, 10]");
    let sc = Scenario::from_toml_str(&text, dir.path()).unwrap();
    let world = World::new(&sc).unwrap();
    for p in world.poses() {
        assert!(p.pos.x >= 0.25 + R, "robot at {:?} in the mask", p.pos);
    }
}

#[test]
fn robots_are_placed_off_obstacles_or_refused() {
    let e = err(
        "[[obstacles]]\nshape = \"disc\"\ncentre = [0.5, 0.5]\nradius = 0.1\n\
         [[robots]]\ncount = 1\nbehaviour = \"avoid\"\nplacement = \"explicit\"\nposes = [[0.55, 0.5, 0]]\n",
    );
    assert!(
        e.contains("robots[1].poses[0]") && e.contains("obstacles[0]"),
        "{e}"
    );
    // Random placement in an arena a third covered by a box never starts a robot on it.
    let sc = Scenario::from_toml_str(
        &format!("{BASE}[[obstacles]]\nshape = \"box\"\ncentre = [0.5, 0.5]\nsize = [0.6, 0.6]\n"),
        ".",
    )
    .unwrap();
    let obs = sc.obstacles().unwrap();
    for seed in 0..5 {
        let sc = sc.clone().with_overrides(Some(seed), None).unwrap();
        let world = World::new(&sc).unwrap();
        for p in world.poses() {
            assert!(
                obs.overlapping(p.pos, R, 0.0).is_none(),
                "seed {seed}: {:?}",
                p.pos
            );
        }
    }
}

#[test]
fn the_grid_finds_what_a_scan_of_every_part_finds() {
    use parry2d::query::Ray;
    // 60 small obstacles of every shape scattered over the arena; 2,000 random rays.
    let mut text = String::new();
    let mut rng = rand::rngs::StdRng::seed_from_u64(11);
    for k in 0..60 {
        let c = Vec2::new(rng.random_range(0.1..0.9), rng.random_range(0.1..0.9));
        text += &match k % 4 {
            0 => format!(
                "[[obstacles]]\nshape = \"box\"\ncentre = [{}, {}]\nsize = [0.05, 0.02]\nangle = {}\n",
                c.x,
                c.y,
                k * 13
            ),
            1 => format!(
                "[[obstacles]]\nshape = \"disc\"\ncentre = [{}, {}]\nradius = 0.03\n",
                c.x, c.y
            ),
            2 => format!(
                "[[obstacles]]\nshape = \"wall\"\npoints = [[{}, {}], [{}, {}]]\nthickness = 0.005\n",
                c.x - 0.05,
                c.y,
                c.x + 0.05,
                c.y + 0.02
            ),
            _ => format!(
                "[[obstacles]]\nshape = \"polygon\"\npoints = [[{}, {}], [{}, {}], [{}, {}], [{}, {}]]\n",
                c.x - 0.04,
                c.y - 0.04,
                c.x + 0.04,
                c.y - 0.04,
                c.x,
                c.y - 0.01,
                c.x - 0.04,
                c.y + 0.04
            ),
        };
    }
    let obs = obstacles(&text);
    for _ in 0..2000 {
        let o = Vec2::new(rng.random_range(0.0..1.0), rng.random_range(0.0..1.0));
        let d = Vec2::from_angle(rng.random_range(-3.2..3.2));
        let max = rng.random_range(0.0..0.1);
        let scan = obs
            .parts()
            .iter()
            .filter_map(|p| p.shape.cast_ray(&p.pose, &Ray::new(o, d), max, true))
            .fold(max, f32::min);
        let grid = obs.ray(o, d, max);
        assert!(
            close(grid, scan, 1e-6),
            "ray {o:?} {d:?} {max}: grid {grid}, scan {scan}"
        );
        let mut three = [max; 3];
        obs.rays(o, max, &[o; 3], &[d; 3], &mut three);
        assert!(close(three[0], scan, 1e-6), "rays: {three:?} vs {scan}");
    }
}

const DISC_ARENA: &str = r#"
duration = 1.0
[screen]
size = [1.0, 1.0]
resolution = [200, 200]
[arena]
shape = { disc = { centre = [0.5, 0.5], radius = 0.45 } }
"#;

#[test]
fn a_disc_arena_holds_its_robots() {
    let text = format!("{DISC_ARENA}[[robots]]\ncount = 40\nbehaviour = \"avoid\"\n");
    let sc = Scenario::from_toml_str(&text, ".").unwrap();
    let obs = Arc::new(sc.obstacles().unwrap());
    // Bumper: facing the wall 1 cm from the rim (the wall's inner face is the disc's edge).
    let r = bumpers(&obs, Pose::new(0.5 + 0.45 - R - 0.01, 0.5, 0.0));
    assert!(close(r[1], 0.5, 1e-2), "{r:?}");
    for backend in BACKENDS {
        let world = World::new(&sc).unwrap();
        let poses = world.poses().to_vec();
        for p in &poses {
            assert!(obs.holds(p.pos, R), "{backend:?}: placed at {:?}", p.pos);
        }
        let mut phys = physics_among(&obs, &poses, backend);
        drive_randomly(&mut phys, 5, 3000, (0.0..0.35, -3.0..3.0), |step, poses| {
            for p in poses {
                // Within the disc, up to 2 mm into its wall.
                assert!(
                    p.pos.distance(Vec2::splat(0.5)) <= 0.45 - R + 0.002,
                    "{backend:?} step {step}: {:?} left the disc",
                    p.pos
                );
            }
        });
    }
}

#[test]
fn arena_shapes_are_checked() {
    let e = err("[arena]\nshape = { disc = { centre = [0.5, 0.5], radius = 0.6 } }\n");
    assert!(
        e.contains("arena.shape") && e.contains("outside the arena"),
        "{e}"
    );
    let e = err("[arena]\nshape = { polygon = [[0.1, 0.1], [0.9, 0.1], [0.5, 0.1]] }\n");
    assert!(e.contains("arena.shape") && e.contains("no area"), "{e}");
    let text = DISC_ARENA.to_string()
        + "[[robots]]\ncount = 1\nbehaviour = \"avoid\"\nplacement = \"explicit\"\nposes = [[0.05, 0.05, 0]]\n";
    let e = Scenario::from_toml_str(&text, ".").unwrap_err().to_string();
    assert!(
        e.contains("robots[0].poses[0]") && e.contains("outside the arena's shape"),
        "{e}"
    );
    // A concave (L-shaped) arena: random placement keeps to the L.
    let l = "[arena]\nshape = { polygon = [[0.05, 0.05], [0.95, 0.05], [0.95, 0.4], [0.4, 0.4], [0.4, 0.95], [0.05, 0.95]] }\n";
    let sc = Scenario::from_toml_str(&format!("{BASE}{l}"), ".").unwrap();
    let world = World::new(&sc).unwrap();
    for p in world.poses() {
        assert!(
            p.pos.x <= 0.4 || p.pos.y <= 0.4,
            "placed at {:?} in the L's notch",
            p.pos
        );
    }
}

#[test]
fn the_same_seed_gives_the_same_run_whatever_the_thread_count() {
    // 100 robots (the sense stage runs in parallel from 64) among obstacles of every shape.
    for physics in ["rapier", "discs"] {
        let text = format!(
            "physics = \"{physics}\"\n{}{}",
            BASE.replace("count = 20", "count = 100"),
            EVERY_SHAPE
        );
        let sc = Scenario::from_toml_str(&text, ".").unwrap();
        let run = |threads: usize| {
            on_threads(threads, || {
                let mut world = World::new(&sc).unwrap();
                for _ in 0..150 {
                    world.step();
                }
                let bumpers: Vec<[f32; 3]> =
                    world.observations().iter().map(|o| o.bumpers).collect();
                (world.poses().to_vec(), bumpers)
            })
        };
        let (one, two) = (run(1), run(2));
        assert!(
            one.1.iter().any(|b| b.iter().any(|&x| x > 0.0)),
            "{physics}: no bumper fired"
        );
        assert_eq!(one, two, "{physics}: 1 and 2 threads differ");
    }
}

#[test]
fn obstacles_and_arena_shapes_survive_the_saved_scenario() {
    for shape in [
        "{ disc = { centre = [0.5, 0.5], radius = 0.45 } }",
        "{ polygon = [[0.05, 0.05], [0.95, 0.05], [0.95, 0.4], [0.4, 0.4], [0.4, 0.95], [0.05, 0.95]] }",
    ] {
        let text = format!(
            "duration = 1.0\n[screen]\nsize = [1.0, 1.0]\nresolution = [200, 200]\n\
             [arena]\nshape = {shape}\n[[obstacles]]\nshape = \"box\"\ncentre = [0.2, 0.2]\n\
             size = [0.05, 0.05]\nangle = 10.0\n[[robots]]\ncount = 5\nbehaviour = \"avoid\"\n"
        );
        let sc = Scenario::from_toml_str(&text, ".").unwrap();
        let again = Scenario::from_toml_str(&sc.to_toml_standalone(), ".").unwrap();
        assert_eq!(again.spec.arena.shape, sc.spec.arena.shape);
        assert_eq!(again.spec.obstacles.len(), 1);
        assert_eq!(again.spec.obstacles[0].angle, Some(10.0));
        let (a, b) = (World::new(&sc).unwrap(), World::new(&again).unwrap());
        assert_eq!(a.poses(), b.poses());
    }
}
