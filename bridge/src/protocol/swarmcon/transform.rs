//! Converts tracker poses (origin at the top-left calibration pattern, y down, yaw in degrees in
//! image axes) to the simulator's frame (origin bottom-left, y up, heading in radians CCW from +x),
//! once, at the edge; with a screen calibration, through its homography, parallax correction and
//! heading sign and offset instead of the nominal frame change.

use super::SlotPose;
use crate::geometry::{ScreenMap, wrap_pi};
use colcos_sim::Vec2;
use colcos_sim::robot::Pose;

/// The tracker-to-simulator frame change.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrameTransform {
    /// Arena height (its extent along the simulator's y), m.
    pub arena_height: f64,
    /// Where the tracker's (0,0) lies from the arena's top-left corner, in tracker axes (x right,
    /// y down), m: the calibration patterns sit inset by the robot radius.
    pub offset: (f64, f64),
    /// A measured screen calibration: when set, it replaces the nominal frame change.
    pub screen: Option<ScreenMap>,
}

/// Wraps an angle in degrees to (-180, 180].
fn wrap_180(a: f64) -> f64 {
    let w = a.rem_euclid(360.0);
    if w > 180.0 { w - 360.0 } else { w }
}

impl FrameTransform {
    /// Tracker origin at the arena's top-left corner.
    pub fn new(arena_height: f64) -> Self {
        FrameTransform {
            arena_height,
            offset: (0.0, 0.0),
            screen: None,
        }
    }

    pub fn with_offset(arena_height: f64, dx: f64, dy: f64) -> Self {
        FrameTransform {
            arena_height,
            offset: (dx, dy),
            screen: None,
        }
    }

    /// Converts through a measured screen calibration.
    pub fn with_screen(self, map: ScreenMap) -> Self {
        FrameTransform {
            screen: Some(map),
            ..self
        }
    }

    /// Tracker (x, y, yaw_deg) to simulator (x, y, heading_rad), in f64 (NaN where a calibration's
    /// homography is undefined: such a pose is not used).
    pub fn to_sim_f64(&self, x: f64, y: f64, yaw_deg: f64) -> (f64, f64, f64) {
        if let Some(map) = &self.screen {
            return map
                .to_sim(x, y, yaw_deg)
                .unwrap_or((f64::NAN, f64::NAN, f64::NAN));
        }
        let sx = self.offset.0 + x;
        let sy = self.arena_height - (self.offset.1 + y);
        // Flipping y mirrors the rotation sense: clockwise-positive image yaw becomes CCW heading.
        (sx, sy, wrap_pi(-yaw_deg.to_radians()))
    }

    /// Simulator (x, y, heading_rad) to tracker (x, y, yaw_deg), in f64.
    pub fn to_tracker_f64(&self, x: f64, y: f64, heading: f64) -> (f64, f64, f64) {
        if let Some(map) = &self.screen {
            return map
                .to_tracker(x, y, heading)
                .unwrap_or((f64::NAN, f64::NAN, f64::NAN));
        }
        let tx = x - self.offset.0;
        let ty = self.arena_height - y - self.offset.1;
        (tx, ty, wrap_180(-heading.to_degrees()))
    }

    /// A slot's pose in the simulator's frame.
    pub fn to_sim(&self, slot: &SlotPose) -> Pose {
        let (x, y, h) = self.to_sim_f64(slot.x, slot.y, slot.yaw_deg);
        Pose {
            pos: Vec2::new(x as f32, y as f32),
            heading: h as f32,
        }
    }

    /// A simulator pose as tracker (x, y, yaw_deg), for a twin server.
    pub fn to_tracker(&self, pose: &Pose) -> (f64, f64, f64) {
        self.to_tracker_f64(pose.pos.x as f64, pose.pos.y as f64, pose.heading as f64)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn corners_and_headings() {
        let t = FrameTransform::new(0.809);
        let (x, y, h) = t.to_sim_f64(0.0, 0.0, 90.0);
        assert_eq!((x, y), (0.0, 0.809));
        // 90 degrees in image axes points down the screen: -pi/2 in the simulator.
        assert!((h + PI / 2.0).abs() < 1e-12);
        let (x, y, _) = t.to_sim_f64(1.439, 0.809, 0.0);
        assert!((x - 1.439).abs() < 1e-12 && y.abs() < 1e-12);
    }

    #[test]
    fn round_trip_with_offset() {
        let t = FrameTransform::with_offset(0.809, 0.02, 0.03);
        for &(x, y, yaw) in &[(0.1, 0.2, 30.0), (-0.05, 0.7, -170.0), (1.3, -0.01, 179.5)] {
            let (sx, sy, sh) = t.to_sim_f64(x, y, yaw);
            let (bx, by, byaw) = t.to_tracker_f64(sx, sy, sh);
            assert!((bx - x).abs() < 1e-12 && (by - y).abs() < 1e-12);
            assert!((byaw - yaw).abs() < 1e-9, "{byaw} vs {yaw}");
        }
    }
}
