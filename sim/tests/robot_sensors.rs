//! IR bumpers, neighbour index, and the colour-sensor layout.
use colcos_sim::robot::Pose;
use colcos_sim::sensors::{
    BumperParams, BumperRays, NeighbourIndex, SENSOR_RADIUS, ray_disc, ray_walls,
    reading_for_distance, sensor_positions, sensor_positions_facing,
};
use glam::Vec2;
use std::f32::consts::{FRAC_PI_2, FRAC_PI_4};

const R: f32 = 0.02;

fn readings(poses: &[Pose], arena: Vec2, i: usize) -> [f32; 3] {
    let params = BumperParams::default();
    let mut index = NeighbourIndex::default();
    let pos: Vec<Vec2> = poses.iter().map(|p| p.pos).collect();
    index.rebuild(arena, NeighbourIndex::cell_for(R, &params), &pos);
    index.bumpers(i, poses, R, arena, &BumperRays::new(&params))
}

#[test]
fn wall_ahead_at_one_centimetre_reads_a_half() {
    let arena = Vec2::new(1.0, 1.0);
    // Rim at x = 0.99 - 0.01: centre 0.97 - 0.0... rim 1 cm from the wall at x = 1.
    let me = Pose::new(1.0 - 0.01 - R, 0.5, 0.0);
    let r = readings(&[me], arena, 0);
    assert!((r[1] - 0.5).abs() < 1e-4, "front {r:?}");
    // The diagonal sensors see the wall at 1 cm / cos 45 from their own rim points... farther.
    assert!(r[0] < r[1] && r[2] < r[1] && (r[0] - r[2]).abs() < 1e-5);
    let far = readings(&[Pose::new(0.5, 0.5, 0.0)], arena, 0);
    assert_eq!(far, [0.0; 3]);
    // Facing away from the near wall: nothing.
    let away = readings(
        &[Pose::new(1.0 - 0.01 - R, 0.5, std::f32::consts::PI)],
        arena,
        0,
    );
    assert_eq!(away, [0.0; 3]);
}

#[test]
fn robot_ahead_left_triggers_front_left_more() {
    let arena = Vec2::new(1.0, 1.0);
    let me = Pose::new(0.5, 0.5, 0.3);
    let other = Pose::new(0.0, 0.0, 0.0);
    let other = Pose {
        pos: me.to_world(Vec2::new(0.045, 0.03)),
        ..other
    };
    let r = readings(&[me, other], arena, 0);
    assert!(r[0] > 0.0, "{r:?}");
    assert!(r[0] > r[2], "{r:?}");
    // Mirror: ahead-right.
    let other = Pose {
        pos: me.to_world(Vec2::new(0.045, -0.03)),
        ..other
    };
    let r = readings(&[me, other], arena, 0);
    assert!(r[2] > r[0], "{r:?}");
}

#[test]
fn robot_straight_ahead_reads_by_distance() {
    let arena = Vec2::new(1.0, 1.0);
    let me = Pose::new(0.3, 0.3, FRAC_PI_2);
    // The other robot's rim 5 mm in front of my rim.
    let other = Pose::new(0.3, 0.3 + 2.0 * R + 0.005, 0.0);
    let r = readings(&[me, other], arena, 0);
    assert!(
        (r[1] - reading_for_distance(0.005, 0.02)).abs() < 1e-3,
        "{r:?}"
    );
    assert!((r[1] - 0.75).abs() < 1e-3);
    // Overlapping robots: the sensor inside the other disc reads 1.
    let other = Pose::new(0.3, 0.3 + 2.0 * R - 0.004, 0.0);
    assert_eq!(readings(&[me, other], arena, 0)[1], 1.0);
    // Robot behind: nothing.
    let behind = Pose::new(0.3, 0.3 - 2.0 * R - 0.002, 0.0);
    assert_eq!(readings(&[me, behind], arena, 0), [0.0; 3]);
}

#[test]
fn index_finds_the_same_as_brute_force() {
    let arena = Vec2::new(1.4, 0.8);
    let mut s = 12345u32;
    let mut next = move || {
        s = s.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        (s >> 8) as f32 / (1u32 << 24) as f32
    };
    let poses: Vec<Pose> = (0..400)
        .map(|_| {
            Pose::new(
                R + next() * (arena.x - 2.0 * R),
                R + next() * (arena.y - 2.0 * R),
                next() * 6.0,
            )
        })
        .collect();
    let params = BumperParams::default();
    let pos: Vec<Vec2> = poses.iter().map(|p| p.pos).collect();
    let mut index = NeighbourIndex::default();
    // A whole-arena cell is brute force.
    index.rebuild(arena, 10.0, &pos);
    let brute: Vec<[f32; 3]> = (0..poses.len())
        .map(|i| index.bumpers(i, &poses, R, arena, &BumperRays::new(&params)))
        .collect();
    let mut hits = 0;
    for cell in [NeighbourIndex::cell_for(R, &params), 0.03, 0.2] {
        index.rebuild(arena, cell, &pos);
        for (i, b) in brute.iter().enumerate() {
            assert_eq!(
                index.bumpers(i, &poses, R, arena, &BumperRays::new(&params)),
                *b,
                "robot {i} cell {cell}"
            );
            hits += b.iter().filter(|&&v| v > 0.0).count();
        }
    }
    assert!(hits > 0);
}

#[test]
fn ray_disc_geometry() {
    let d = Vec2::X;
    assert!((ray_disc(Vec2::ZERO, d, Vec2::new(0.05, 0.0), 0.02).unwrap() - 0.03).abs() < 1e-6);
    assert_eq!(ray_disc(Vec2::ZERO, d, Vec2::new(-0.05, 0.0), 0.02), None);
    assert_eq!(ray_disc(Vec2::ZERO, d, Vec2::new(0.05, 0.03), 0.02), None);
    assert_eq!(
        ray_disc(Vec2::ZERO, d, Vec2::new(0.01, 0.0), 0.02),
        Some(0.0)
    );
    assert_eq!(reading_for_distance(0.03, 0.02), 0.0);
    assert_eq!(reading_for_distance(0.0, 0.02), 1.0);
}

#[test]
fn default_bumper_angles() {
    let p = BumperParams::default();
    assert_eq!(p.angles, [FRAC_PI_4, 0.0, -FRAC_PI_4]);
}

#[test]
fn sensor_positions_follow_the_heading() {
    let r = SENSOR_RADIUS;
    let close = |a: Vec2, b: Vec2| (a - b).length() < 1e-6;
    let p = Pose::new(1.0, 2.0, 0.0);
    let s = sensor_positions(&p, r);
    // Y- (right), X+ (front), Y+ (left), X- (back).
    assert!(close(s[0], Vec2::new(1.0, 2.0 - r)));
    assert!(close(s[1], Vec2::new(1.0 + r, 2.0)));
    assert!(close(s[2], Vec2::new(1.0, 2.0 + r)));
    assert!(close(s[3], Vec2::new(1.0 - r, 2.0)));
    // Facing +y: front is +y, left is -x.
    let s = sensor_positions(&Pose::new(1.0, 2.0, FRAC_PI_2), r);
    assert!(close(s[0], Vec2::new(1.0 + r, 2.0)));
    assert!(close(s[1], Vec2::new(1.0, 2.0 + r)));
    assert!(close(s[2], Vec2::new(1.0 - r, 2.0)));
    assert!(close(s[3], Vec2::new(1.0, 2.0 - r)));
}

/// A lone robot's wall readings (which skip the wall test far from every wall) equal the readings of
/// `ray_walls` itself, bit for bit, over the whole arena and every heading; and the sensor positions
/// from a precomputed heading vector are `sensor_positions`'.
#[test]
fn wall_readings_equal_ray_walls_everywhere() {
    let params = BumperParams::default();
    let arena = Vec2::new(1.2, 0.8);
    let mut lit = 0;
    for i in 0..=240 {
        for j in 0..=160 {
            let pose = Pose::new(
                -0.002 + i as f32 * 0.005,
                -0.002 + j as f32 * 0.005,
                (i * 7 + j * 13) as f32 * 0.1,
            );
            let got = readings(&[pose], arena, 0);
            let want = params.angles.map(|a| {
                let d = pose.forward().rotate(Vec2::from_angle(a));
                let t = ray_walls(pose.pos + R * d, d, arena);
                reading_for_distance(params.range.min(t), params.range)
            });
            assert_eq!(got, want, "at {pose:?}");
            lit += usize::from(got.iter().any(|&r| r > 0.0));
            assert_eq!(
                sensor_positions_facing(&pose, pose.forward(), SENSOR_RADIUS),
                sensor_positions(&pose, SENSOR_RADIUS)
            );
        }
    }
    assert!(lit > 1000, "only {lit} poses see a wall");
}
