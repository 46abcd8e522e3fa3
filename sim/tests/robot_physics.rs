//! rapier2d arena: walls hold, contacts separate, runs repeat bit for bit.
use colcos_sim::arena::Obstacles;
use colcos_sim::robot::{ArenaPhysics, ColiasParams, PhysicsBackend, Pose};
use glam::Vec2;
use proptest::prelude::*;
use std::sync::Arc;

const DT: f32 = 0.02;
const BACKENDS: [PhysicsBackend; 2] = [PhysicsBackend::Rapier, PhysicsBackend::Discs];

fn inside(phys: &ArenaPhysics, size: Vec2, r: f32) {
    for (i, p) in phys.poses().iter().enumerate() {
        let ok = p.pos.x >= r - 1e-3
            && p.pos.x <= size.x - r + 1e-3
            && p.pos.y >= r - 1e-3
            && p.pos.y <= size.y - r + 1e-3;
        assert!(ok, "robot {i} at {:?} left the arena", p.pos);
    }
}

/// A grid of robots with spacing `gap` (m) between centres.
/// Robots with the default body at `poses` in a 1 m x 1 m arena, moved by `backend`.
fn unit_arena(poses: &[Pose], backend: PhysicsBackend) -> ArenaPhysics {
    ArenaPhysics::with_backend(Vec2::ONE, &ColiasParams::default(), poses, backend)
}

fn grid(n: usize, size: Vec2, gap: f32) -> Vec<Pose> {
    let cols = ((size.x - 2.0 * gap) / gap).floor().max(1.0) as usize;
    (0..n)
        .map(|i| {
            Pose::new(
                gap + (i % cols) as f32 * gap,
                gap + (i / cols) as f32 * gap,
                (i as f32 * 2.39) % 6.0,
            )
        })
        .collect()
}

#[test]
fn full_speed_into_a_corner_stays_inside() {
    for backend in BACKENDS {
        let p = ColiasParams::default();
        let size = Vec2::new(0.5, 0.4);
        let mut phys =
            ArenaPhysics::with_backend(size, &p, &[Pose::new(0.25, 0.2, 0.6435)], backend);
        for _ in 0..300 {
            phys.step(&[(p.max_wheel_speed, 0.0)], DT);
            inside(&phys, size, p.radius);
        }
        let q = phys.poses()[0].pos;
        assert!(
            q.x > size.x - p.radius - 0.003 && q.y > size.y - p.radius - 0.003,
            "not in the corner: {q:?}"
        );
    }
}

#[test]
fn a_hundred_robots_pushed_into_a_wall_stay_inside() {
    for backend in BACKENDS {
        let p = ColiasParams::default();
        let size = Vec2::new(1.4, 0.8);
        let poses: Vec<Pose> = grid(100, size, 0.06)
            .into_iter()
            .map(|q| Pose { heading: 0.0, ..q })
            .collect();
        let mut phys = ArenaPhysics::with_backend(size, &p, &poses, backend);
        let v = vec![(p.max_wheel_speed, 0.0); 100];
        for _ in 0..500 {
            phys.step(&v, DT);
            inside(&phys, size, p.radius);
        }
        // Piled against the wall, they still hardly overlap.
        let q = phys.poses();
        let mut worst = 0.0f32;
        for a in 0..q.len() {
            for b in a + 1..q.len() {
                worst = worst.max(2.0 * p.radius - (q[a].pos - q[b].pos).length());
            }
        }
        assert!(worst < 0.002, "{backend:?}: overlap {worst} m");
    }
}

/// The largest overlap (diameter minus centre distance; negative while apart) of two robots that
/// start facing each other at x = `from` and `to` m (y = 0.5 m) and drive at full speed for 4 s.
fn head_on_overlap(from: f32, to: f32, backend: PhysicsBackend) -> f32 {
    let p = ColiasParams::default();
    let facing = [
        Pose::new(from, 0.5, 0.0),
        Pose::new(to, 0.5, std::f32::consts::PI),
    ];
    let mut phys = unit_arena(&facing, backend);
    let mut worst = f32::NEG_INFINITY;
    for _ in 0..200 {
        phys.step(&[(p.max_wheel_speed, 0.0); 2], DT);
        let d = (phys.poses()[0].pos - phys.poses()[1].pos).length();
        worst = worst.max(2.0 * p.radius - d);
    }
    worst
}

#[test]
fn head_on_robots_do_not_overlap() {
    for backend in BACKENDS {
        let overlap = head_on_overlap(0.3, 0.7, backend);
        assert!(overlap < 0.002, "{backend:?}: overlap {overlap} m");
    }
}

#[test]
fn set_pose_teleports() {
    for backend in BACKENDS {
        let p = ColiasParams::default();
        let mut phys = unit_arena(&[Pose::new(0.3, 0.5, 0.0)], backend);
        assert_eq!(phys.len(), 1);
        phys.set_pose(0, Pose::new(0.6, 0.4, 1.0));
        assert_eq!(phys.poses()[0], Pose::new(0.6, 0.4, 1.0));
        phys.step(&[(0.0, 0.0)], DT);
        assert!((phys.poses()[0].pos - Vec2::new(0.6, 0.4)).length() < 1e-6);
        assert!((phys.poses()[0].heading - 1.0).abs() < 1e-6);
        // Outside the arena: clamped in.
        phys.set_pose(0, Pose::new(-1.0, 2.0, 0.0));
        assert_eq!(phys.poses()[0].pos, Vec2::new(p.radius, 1.0 - p.radius));
    }
}

fn run(seed: u32, backend: PhysicsBackend) -> Vec<Pose> {
    let p = ColiasParams::default();
    let size = Vec2::new(1.4, 0.8);
    let mut phys = ArenaPhysics::with_backend(size, &p, &grid(60, size, 0.08), backend);
    let mut s = seed;
    let mut next = move || {
        s = s.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        (s >> 8) as f32 / (1u32 << 24) as f32
    };
    for _ in 0..300 {
        let v: Vec<(f32, f32)> = (0..60)
            .map(|_| (0.35 * next(), 10.0 * (next() - 0.5)))
            .collect();
        phys.step(&v, DT);
    }
    phys.poses().to_vec()
}

#[test]
fn physics_is_deterministic() {
    for backend in BACKENDS {
        let a = run(3, backend);
        let b = run(3, backend);
        for (p, q) in a.iter().zip(&b) {
            assert_eq!(p.pos.x.to_bits(), q.pos.x.to_bits());
            assert_eq!(p.pos.y.to_bits(), q.pos.y.to_bits());
            assert_eq!(p.heading.to_bits(), q.heading.to_bits());
        }
        assert_ne!(a, run(4, backend));
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 8, .. ProptestConfig::default() })]

    #[test]
    fn robots_never_leave_the_arena(
        commands in prop::collection::vec((-0.5f32..0.5, -30.0f32..30.0), 50 * 10),
        w in 0.5f32..1.5,
        h in 0.4f32..1.0,
        discs in any::<bool>(),
    ) {
        let backend = if discs { PhysicsBackend::Discs } else { PhysicsBackend::Rapier };
        let p = ColiasParams::default();
        let size = Vec2::new(w, h);
        let mut phys = ArenaPhysics::with_backend(size, &p, &grid(50, size, 0.05), backend);
        // 500 steps; the commands change every 50 steps.
        for k in 0..500 {
            let block = (k / 50) * 50;
            let v: Vec<(f32, f32)> = commands[block..block + 50].to_vec();
            phys.step(&v, DT);
            for q in phys.poses() {
                prop_assert!(q.pos.x >= p.radius - 1e-3 && q.pos.x <= w - p.radius + 1e-3);
                prop_assert!(q.pos.y >= p.radius - 1e-3 && q.pos.y <= h - p.radius + 1e-3);
            }
        }
    }
}

/// Six robots in a small arena under random commands: steps with and without rapier's pipeline
/// (a step in which no contact is possible) give the same poses, bit for bit, as rapier alone.
#[test]
fn free_steps_are_bit_identical_to_rapier() {
    for seed in [7, 11, 23, 99] {
        free_steps_match(seed, None);
    }
    // A box and a disc in the middle of the arena.
    let text = "duration = 1.0\n[[obstacles]]\nshape = \"box\"\ncentre = [0.25, 0.2]\nsize = [0.08, 0.05]\n\
                [[obstacles]]\nshape = \"disc\"\ncentre = [0.4, 0.3]\nradius = 0.03\n";
    let spec = colcos_sim::scenario::parse_spec(text).unwrap();
    let obstacles = Obstacles::build(
        &spec.obstacles,
        Vec2::new(0.5, 0.4),
        std::path::Path::new("."),
    )
    .unwrap();
    for seed in [5, 42] {
        free_steps_match(seed, Some(Arc::new(obstacles.clone())));
    }
}

fn free_steps_match(seed: u32, obstacles: Option<Arc<Obstacles>>) {
    let p = ColiasParams::default();
    let size = Vec2::new(0.5, 0.4);
    let start: Vec<Pose> = match &obstacles {
        // A row along the top, clear of the obstacles.
        Some(_) => (0..6)
            .map(|i| Pose::new(0.06 + 0.076 * i as f32, 0.36, i as f32))
            .collect(),
        None => grid(6, size, 0.1),
    };
    let mut fast = ArenaPhysics::with_backend(size, &p, &start, PhysicsBackend::Rapier);
    let mut slow = ArenaPhysics::with_backend(size, &p, &start, PhysicsBackend::Rapier);
    if let Some(obs) = obstacles {
        fast.set_obstacles(obs.clone());
        slow.set_obstacles(obs);
    }
    slow.set_free_steps(false);
    let mut s = seed;
    let mut next = move || {
        s = s.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        (s >> 8) as f32 / (1u32 << 24) as f32
    };
    let (mut touching, mut apart) = (0, 0);
    let mut v = vec![(0.0, 0.0); 6];
    for k in 0..3000 {
        if k % 25 == 0 {
            for c in &mut v {
                *c = (0.7 * (next() - 0.3), 20.0 * (next() - 0.5));
            }
        }
        if k == 1500 {
            // A teleport between free steps keeps the other robots' free moves.
            fast.set_pose(2, Pose::new(0.25, 0.2, 1.0));
            slow.set_pose(2, Pose::new(0.25, 0.2, 1.0));
        }
        fast.step(&v, DT);
        slow.step(&v, DT);
        for (i, (a, b)) in fast.poses().iter().zip(slow.poses()).enumerate() {
            let bits = |q: &Pose| (q.pos.x.to_bits(), q.pos.y.to_bits(), q.heading.to_bits());
            assert_eq!(
                bits(a),
                bits(b),
                "robot {i} differs at step {k}: {a:?} vs {b:?}"
            );
        }
        let q = fast.poses();
        let gap = (0..6)
            .flat_map(|i| (i + 1..6).map(move |j| (i, j)))
            .map(|(i, j)| (q[i].pos - q[j].pos).length())
            .fold(f32::INFINITY, f32::min);
        if gap < 2.0 * p.radius + 0.005 {
            touching += 1;
        } else if gap > 2.0 * p.radius + 0.03 {
            apart += 1;
        }
    }
    // Both kinds of step happened.
    assert!(
        touching > 100 && apart > 100,
        "touching {touching}, apart {apart}"
    );
}

/// In free space a robot driven at constant speed goes `v t` along its heading and turns by
/// `omega t` (both solvers; rapier's linearised rotation is within 1e-4 rad over 1 s).
#[test]
fn constant_speed_in_free_space_is_analytic() {
    for backend in BACKENDS {
        let (v, heading) = (0.2f32, 0.5f32);
        let start = Pose::new(0.3, 0.3, heading);
        let mut phys = unit_arena(&[start], backend);
        for _ in 0..50 {
            phys.step(&[(v, 0.0)], DT);
        }
        let expected = start.pos + Vec2::from_angle(heading) * v * 1.0;
        let q = phys.poses()[0];
        assert!(
            (q.pos - expected).length() < 1e-5,
            "{backend:?}: {q:?} vs {expected:?}"
        );
        assert!((q.heading - heading).abs() < 1e-5);
        // Turning on the spot: 0.4 rad/s for 1 s.
        for _ in 0..50 {
            phys.step(&[(0.0, 0.4)], DT);
        }
        let q2 = phys.poses()[0];
        assert!((q2.pos - q.pos).length() < 1e-6);
        assert!(
            (q2.heading - (heading + 0.4)).abs() < 1e-4,
            "{backend:?}: {}",
            q2.heading
        );
    }
}

/// Two robots driven into each other side by side for 4 s overlap by at most 1 mm.
#[test]
fn robots_pushed_together_overlap_at_most_a_millimetre() {
    for backend in BACKENDS {
        let worst = head_on_overlap(0.45, 0.55, backend);
        assert!(worst <= 1e-3, "{backend:?}: overlap {worst} m");
    }
}
