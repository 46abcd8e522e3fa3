//! Differential drive: motor lag, limits, body velocities; and straight/spin motion through the physics.
use colcos_sim::behaviour::WheelCommand;
use colcos_sim::robot::{ArenaPhysics, ColiasParams, DriveState, Pose};
use glam::Vec2;

const DT: f32 = 0.02;

#[test]
fn lag_follows_the_analytic_first_order_response() {
    let p = ColiasParams::default();
    let cmd = WheelCommand::new(0.2, -0.1);
    let mut d = DriveState::default();
    for k in 1..=50 {
        d.update(cmd, &p, DT);
        let t = k as f32 * DT;
        let f = 1.0 - (-t / p.motor_lag).exp();
        assert!(
            (d.left - 0.2 * f).abs() < 1e-5,
            "left at {t}: {} vs {}",
            d.left,
            0.2 * f
        );
        assert!((d.right + 0.1 * f).abs() < 1e-5, "right at {t}");
    }
}

#[test]
fn lag_is_exact_for_any_step() {
    // One step of 0.1 s equals ten of 0.01 s.
    let p = ColiasParams::default();
    let cmd = WheelCommand::new(0.3, 0.1);
    let (mut a, mut b) = (DriveState::default(), DriveState::default());
    a.update(cmd, &p, 0.1);
    for _ in 0..10 {
        b.update(cmd, &p, 0.01);
    }
    assert!((a.left - b.left).abs() < 1e-6 && (a.right - b.right).abs() < 1e-6);
}

#[test]
fn zero_lag_is_immediate_and_commands_are_clamped() {
    let p = ColiasParams {
        motor_lag: 0.0,
        ..ColiasParams::default()
    };
    let mut d = DriveState::default();
    d.update(WheelCommand::new(0.1, -0.2), &p, DT);
    assert_eq!((d.left, d.right), (0.1, -0.2));
    d.update(WheelCommand::new(5.0, -5.0), &p, DT);
    assert_eq!((d.left, d.right), (p.max_wheel_speed, -p.max_wheel_speed));
    d.update(WheelCommand::new(f32::NAN, f32::INFINITY), &p, DT);
    assert_eq!((d.left, d.right), (0.0, p.max_wheel_speed));
}

#[test]
fn body_velocity_of_a_differential_drive() {
    let p = ColiasParams::default();
    let d = DriveState {
        left: 0.1,
        right: 0.3,
    };
    let (v, w) = d.body_velocity(&p);
    assert!((v - 0.2).abs() < 1e-6);
    assert!((w - 0.2 / p.wheel_base).abs() < 1e-4);
}

/// Drives one robot in the middle of a big arena with `cmd` for `secs`, returning start and end poses
/// and the distance its wheels should have carried it (the lag integrated analytically).
fn drive(cmd: WheelCommand, heading: f32, secs: f32) -> (Pose, Pose, ColiasParams) {
    let p = ColiasParams::default();
    let start = Pose::new(1.0, 1.0, heading);
    let mut phys = ArenaPhysics::new(Vec2::new(2.0, 2.0), &p, &[start]);
    let mut d = DriveState::default();
    let steps = (secs / DT).round() as usize;
    for _ in 0..steps {
        d.update(cmd, &p, DT);
        phys.step(&[d.body_velocity(&p)], DT);
    }
    (start, phys.poses()[0], p)
}

#[test]
fn straight_drive_covers_speed_times_time() {
    let (start, end, p) = drive(WheelCommand::new(0.2, 0.2), 0.7, 1.0);
    // Distance with the lag: v (t - tau (1 - e^{-t/tau})); the speed is applied after its update, so
    // the discrete lag leads by one step: sum_k v (1 - e^{-k dt / tau}) dt.
    let tau = p.motor_lag;
    let expected: f32 = (1..=50)
        .map(|k| 0.2 * (1.0 - (-(k as f32) * DT / tau).exp()) * DT)
        .sum();
    let moved = end.pos - start.pos;
    assert!(
        (moved.length() - expected).abs() < 0.02 * expected,
        "moved {} expected {expected}",
        moved.length()
    );
    // The no-lag figure is 0.2 m; the lag costs about v * tau.
    assert!((moved.length() + 0.2 * tau - 0.2).abs() < 0.02 * 0.2);
    // Along the heading.
    assert!(moved.normalize().dot(Vec2::from_angle(0.7)) > 0.9999);
    assert!((end.heading - 0.7).abs() < 1e-4);
}

#[test]
fn spinning_in_place_turns_at_the_yaw_rate() {
    let (start, end, p) = drive(WheelCommand::new(-0.05, 0.05), 0.0, 1.0);
    let tau = p.motor_lag;
    let rate = 0.1 / p.wheel_base;
    let expected: f32 = (1..=50)
        .map(|k| rate * (1.0 - (-(k as f32) * DT / tau).exp()) * DT)
        .sum();
    // Unwrap: the turn is less than 2 pi... compare via the wrapped difference.
    let turned = end.heading - start.heading;
    let diff = (turned - expected).rem_euclid(std::f32::consts::TAU);
    let diff = diff.min(std::f32::consts::TAU - diff);
    assert!(
        diff < 0.02 * expected,
        "turned {turned} expected {expected}"
    );
    assert!(
        (end.pos - start.pos).length() < 1e-4,
        "moved {}",
        (end.pos - start.pos).length()
    );
}

/// The heading vectors a world shares between its stages (sensing, physics, the shield, rewards)
/// are its robots' own, bit for bit, as they move and after they are placed by hand.
#[test]
fn a_worlds_shared_heading_vectors_are_its_poses_own() {
    use colcos_sim::world::World;
    let mut world = World::new(&colcos_testkit::scenarios::wanderers(0.08)).unwrap();
    let same = |world: &World| {
        for (i, pose) in world.poses().iter().enumerate() {
            let (shared, own) = (world.forward(i), pose.forward());
            assert_eq!(
                shared.to_array().map(f32::to_bits),
                own.to_array().map(f32::to_bits),
                "robot {i}"
            );
        }
    };
    same(&world);
    for _ in 0..50 {
        world.step();
        same(&world);
    }
    let turned = Pose::new(0.7, 0.4, 2.5);
    world.place_robots(&[(0, turned)]).unwrap();
    same(&world);
    assert_eq!(world.forward(0), Vec2::from_angle(2.5));
}
