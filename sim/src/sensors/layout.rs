//! Where the four colour sensors sit under the robot.
use crate::robot::Pose;
use glam::Vec2;

/// Distance of each sensor from the robot's centre, m (3 cm diagonal).
pub const SENSOR_RADIUS: f32 = 0.015;

/// Arena positions of sensors n = 0..3 at robot-frame (0,-r), (r,0), (0,r), (-r,0): Y-, X+, Y+, X-.
pub fn sensor_positions(pose: &Pose, r: f32) -> [Vec2; 4] {
    [
        pose.to_world(Vec2::new(0.0, -r)),
        pose.to_world(Vec2::new(r, 0.0)),
        pose.to_world(Vec2::new(0.0, r)),
        pose.to_world(Vec2::new(-r, 0.0)),
    ]
}

/// [`sensor_positions`] with the pose's heading vector (`pose.forward()`) computed by the caller:
/// the same positions (`to_world` is `pos + forward.rotate(local)`).
pub fn sensor_positions_facing(pose: &Pose, forward: Vec2, r: f32) -> [Vec2; 4] {
    [
        Vec2::new(0.0, -r),
        Vec2::new(r, 0.0),
        Vec2::new(0.0, r),
        Vec2::new(-r, 0.0),
    ]
    .map(|local| pose.pos + forward.rotate(local))
}
