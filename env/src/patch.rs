//! The egocentric screen patch: what a downward camera under the robot would see, as a small RGB image.
use crate::config::PatchConfig;
use colcos_sim::field::Pheromone;
use colcos_sim::robot::Pose;
use colcos_sim::screen::{ScreenSpec, pixel_at};
use glam::Vec2;

/// Fills `out` (`pixels * pixels * 3` bytes, row-major, RGB) with the screen around `pose`.
///
/// The square spans a quarter of its side behind the robot's centre to three quarters ahead, centred
/// left-right. Row 0 is the far edge ahead, column 0 the robot's left: the image is what the robot
/// would see looking down with its forward direction up.
pub fn sample(
    pheromones: &[Pheromone],
    screen: &ScreenSpec,
    pose: &Pose,
    cfg: &PatchConfig,
    out: &mut [u8],
) {
    let p = cfg.pixels;
    let px = cfg.side / p as f32;
    for row in 0..p {
        // Forward distance of the row's centre: from 3/4 side ahead down to 1/4 side behind.
        let ahead = 0.75 * cfg.side - (row as f32 + 0.5) * px;
        for col in 0..p {
            let left = 0.5 * cfg.side - (col as f32 + 0.5) * px;
            let q = pose.to_world(Vec2::new(ahead, left));
            let rgb = pixel_at(pheromones, screen, q);
            let k = 3 * (row * p + col);
            out[k..k + 3].copy_from_slice(&rgb);
        }
    }
}
