//! The map the bridge applies to every tracker pose at the edge once the screen has been calibrated:
//! tracker coordinates (as on the wire) -> screen pixels by the fitted homography -> metres in our
//! frame -> the marker-height parallax undone; the tracker's yaw (image axes) -> our heading by the
//! fitted sign and offset.
use super::Homography;
use std::f64::consts::PI;

/// Wraps an angle to (-pi, pi].
pub(crate) fn wrap_pi(a: f64) -> f64 {
    let w = a.rem_euclid(2.0 * PI);
    if w > PI { w - 2.0 * PI } else { w }
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ScreenMap {
    /// Tracker (x, y) as on the wire -> screen pixels (continuous, origin at the panel's top-left
    /// corner, pixel `i` covering `[i, i + 1)`).
    pub homography: Homography,
    /// The panel's pixels (width, height).
    pub resolution: [u32; 2],
    /// The panel's size, m.
    pub size: [f64; 2],
    /// The camera's height above the screen, m.
    pub camera_height: f64,
    /// The markers' height above the screen, m.
    pub marker_height: f64,
    /// The point of the screen right under the camera, m, our frame.
    pub nadir: [f64; 2],
    /// Our heading = `heading_sign * (-yaw) + heading_offset` (yaw in radians, image axes).
    pub heading_sign: f64,
    pub heading_offset: f64,
}

impl ScreenMap {
    /// Screen pixels to metres in our frame (origin bottom-left, y up).
    pub fn px_to_m(&self, p: [f64; 2]) -> [f64; 2] {
        [
            p[0] * self.size[0] / self.resolution[0] as f64,
            self.size[1] - p[1] * self.size[1] / self.resolution[1] as f64,
        ]
    }

    /// Metres in our frame to screen pixels.
    pub fn m_to_px(&self, p: [f64; 2]) -> [f64; 2] {
        [
            p[0] * self.resolution[0] as f64 / self.size[0],
            (self.size[1] - p[1]) * self.resolution[1] as f64 / self.size[1],
        ]
    }

    /// Where the camera ray through a marker `marker_height` above `p` meets the screen: pushed away
    /// from the nadir by `H / (H - h)`.
    fn parallax_factor(&self) -> f64 {
        let (hc, hm) = (self.camera_height, self.marker_height);
        if hc > 0.0 && hm >= 0.0 && hm < hc {
            hc / (hc - hm)
        } else {
            1.0
        }
    }

    /// A point on the screen plane (a fiducial) seen at tracker (x, y): metres, our frame.
    pub fn screen_point(&self, x: f64, y: f64) -> Option<[f64; 2]> {
        self.homography.apply([x, y]).map(|p| self.px_to_m(p))
    }

    /// A marker seen at tracker (x, y) with yaw `yaw_deg`: the robot's (x, y, heading) in our frame.
    pub fn to_sim(&self, x: f64, y: f64, yaw_deg: f64) -> Option<(f64, f64, f64)> {
        let seen = self.screen_point(x, y)?;
        let k = self.parallax_factor();
        let n = self.nadir;
        let p = [n[0] + (seen[0] - n[0]) / k, n[1] + (seen[1] - n[1]) / k];
        let heading = wrap_pi(self.heading_sign * -yaw_deg.to_radians() + self.heading_offset);
        Some((p[0], p[1], heading))
    }

    /// The inverse of [`ScreenMap::to_sim`]: what the tracker reports for a robot at (x, y, heading).
    pub fn to_tracker(&self, x: f64, y: f64, heading: f64) -> Option<(f64, f64, f64)> {
        let k = self.parallax_factor();
        let n = self.nadir;
        let seen = [n[0] + (x - n[0]) * k, n[1] + (y - n[1]) * k];
        let t = self.homography.inverse()?.apply(self.m_to_px(seen))?;
        let sign = if self.heading_sign < 0.0 { -1.0 } else { 1.0 };
        let yaw = -wrap_pi((heading - self.heading_offset) * sign);
        Some((t[0], t[1], yaw.to_degrees()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn map() -> ScreenMap {
        ScreenMap {
            homography: Homography([
                [2500.0, 40.0, 30.0],
                [-30.0, 2600.0, 20.0],
                [0.01, -0.02, 1.0],
            ]),
            resolution: [3840, 2160],
            size: [1.439, 0.809],
            camera_height: 1.6,
            marker_height: 0.035,
            nadir: [0.7, 0.4],
            heading_sign: -1.0,
            heading_offset: 0.3,
        }
    }

    #[test]
    fn round_trip() {
        let m = map();
        for &(x, y, h) in &[(0.1, 0.2, 1.0), (1.3, 0.7, -2.9), (0.72, 0.41, 3.1)] {
            let (tx, ty, yaw) = m.to_tracker(x, y, h).unwrap();
            let (bx, by, bh) = m.to_sim(tx, ty, yaw).unwrap();
            assert!((bx - x).abs() < 1e-9 && (by - y).abs() < 1e-9, "{bx} {by}");
            assert!(wrap_pi(bh - h).abs() < 1e-9, "{bh} vs {h}");
        }
    }

    #[test]
    fn markers_far_from_the_nadir_are_pulled_in() {
        let m = map();
        let (tx, ty, _) = m.to_tracker(1.4, 0.8, 0.0).unwrap();
        let seen = m.screen_point(tx, ty).unwrap();
        // 0.7 m from the nadir, a 3.5 cm marker under a 1.6 m camera: seen ~15 mm further out.
        let d = ((seen[0] - 1.4).powi(2) + (seen[1] - 0.8).powi(2)).sqrt();
        assert!(
            (d - 0.0806 * 0.035 / (1.6 - 0.035) * 10.0).abs() < 2e-3,
            "{d}"
        );
    }
}
