//! rapier2d arena: walls hold, contacts separate, runs repeat bit for bit.
use colcos_sim::robot::{ArenaPhysics, ColiasParams, PhysicsBackend, Pose};
use glam::Vec2;
use proptest::prelude::*;

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

#[test]
fn head_on_robots_do_not_overlap() {
    for backend in BACKENDS {
        let p = ColiasParams::default();
        let size = Vec2::new(1.0, 1.0);
        let mut phys = ArenaPhysics::with_backend(
            size,
            &p,
            &[
                Pose::new(0.3, 0.5, 0.0),
                Pose::new(0.7, 0.5, std::f32::consts::PI),
            ],
            backend,
        );
        let mut min_gap = f32::INFINITY;
        for _ in 0..200 {
            phys.step(&[(p.max_wheel_speed, 0.0), (p.max_wheel_speed, 0.0)], DT);
            let d = (phys.poses()[0].pos - phys.poses()[1].pos).length();
            min_gap = min_gap.min(d);
        }
        assert!(
            min_gap > 2.0 * p.radius - 0.002,
            "overlap {} m",
            2.0 * p.radius - min_gap
        );
    }
}

#[test]
fn set_pose_teleports() {
    for backend in BACKENDS {
        let p = ColiasParams::default();
        let mut phys = ArenaPhysics::with_backend(
            Vec2::new(1.0, 1.0),
            &p,
            &[Pose::new(0.3, 0.5, 0.0)],
            backend,
        );
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
