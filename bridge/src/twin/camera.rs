//! The twin's overhead camera, for calibration: a pinhole camera at a set position and tilt above
//! the screen, so that the screen-to-image map is a true homography and a marker on top of a robot
//! shows the parallax a real one does; pixel noise and the odd wild detection; and the tracker's
//! detection of calibration fiducials (white discs on a black frame) in the frames the bridge shows.
use crate::geometry::Homography;
use image::RgbImage;

/// A camera looking down at the screen. Our frame: x right, y up, z up from the screen, m.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraModel {
    /// The camera's centre, m (its (x, y) is the nadir; z its height above the screen).
    pub position: [f64; 3],
    /// Rotation about the vertical, then tilts about the image's x and y axes, rad.
    pub yaw: f64,
    pub pitch: f64,
    pub roll: f64,
    /// Focal length and image size, px (the principal point at the image's centre).
    pub focal_px: f64,
    pub image_size: [u32; 2],
    /// The tracker reports image pixels times this, as "metres" (its own rough scale).
    pub wire_scale: f64,
    /// Height of the markers on the robots above the screen, m.
    pub marker_height: f64,
    /// Standard deviation of a detection's position, image px.
    pub noise_px: f64,
    /// Probability that a fiducial detection is wild (off by 5-20 px).
    pub outlier_rate: f64,
}

impl CameraModel {
    /// A camera like the lab's over a `size` panel: 1.6 m up, a little off centre, rotated 1.5
    /// degrees and tilted under a degree, 960x720 px, markers 3.5 cm high, 0.25 px of noise and 3%
    /// wild fiducial detections.
    pub fn lab(size: [f64; 2]) -> CameraModel {
        let image_size = [960, 720];
        let height = 1.6;
        CameraModel {
            position: [0.5 * size[0] + 0.012, 0.5 * size[1] - 0.009, height],
            yaw: 1.5f64.to_radians(),
            pitch: 0.8f64.to_radians(),
            roll: -0.6f64.to_radians(),
            focal_px: 0.95 * image_size[0] as f64 * height / (size[0] * 1.1),
            image_size,
            wire_scale: size[0] / image_size[0] as f64,
            marker_height: 0.035,
            noise_px: 0.25,
            outlier_rate: 0.03,
        }
    }

    /// World-to-camera rotation (rows are the camera's axes in our frame): looking straight down
    /// with the image's top at the screen's top, then the set yaw, pitch and roll.
    fn rotation(&self) -> [[f64; 3]; 3] {
        let base = [[1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, -1.0]];
        let (sy, cy) = self.yaw.sin_cos();
        let (sp, cp) = self.pitch.sin_cos();
        let (sr, cr) = self.roll.sin_cos();
        let rz = [[cy, -sy, 0.0], [sy, cy, 0.0], [0.0, 0.0, 1.0]];
        let rx = [[1.0, 0.0, 0.0], [0.0, cp, -sp], [0.0, sp, cp]];
        let ry = [[cr, 0.0, sr], [0.0, 1.0, 0.0], [-sr, 0.0, cr]];
        mul(&ry, &mul(&rx, &mul(&rz, &base)))
    }

    /// Image pixel of a point of our frame (x, y, z), `None` behind the camera.
    pub fn project(&self, p: [f64; 3]) -> Option<[f64; 2]> {
        let r = self.rotation();
        let d = [
            p[0] - self.position[0],
            p[1] - self.position[1],
            p[2] - self.position[2],
        ];
        let c: [f64; 3] = std::array::from_fn(|i| r[i][0] * d[0] + r[i][1] * d[1] + r[i][2] * d[2]);
        if c[2] <= 1e-9 {
            return None;
        }
        Some([
            0.5 * self.image_size[0] as f64 + self.focal_px * c[0] / c[2],
            0.5 * self.image_size[1] as f64 + self.focal_px * c[1] / c[2],
        ])
    }

    /// The true map from screen pixels (a `resolution` panel of `size` m) to image pixels.
    pub fn screen_to_image(&self, resolution: [u32; 2], size: [f64; 2]) -> Option<Homography> {
        let corners = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0], [0.5, 0.3]];
        let mut from = Vec::new();
        let mut to = Vec::new();
        for c in corners {
            let px = [c[0] * resolution[0] as f64, c[1] * resolution[1] as f64];
            let m = [c[0] * size[0], size[1] - c[1] * size[1], 0.0];
            from.push(px);
            to.push(self.project(m)?);
        }
        crate::geometry::fit_dlt(&from, &to)
    }

    /// What the tracker reports for a robot at `(x, y)` heading `heading` (our frame): its marker's
    /// image position times the wire scale, and the heading's direction in image axes, degrees.
    pub fn see_marker(
        &self,
        x: f64,
        y: f64,
        heading: f64,
        noise: &mut Noise,
    ) -> Option<(f64, f64, f64)> {
        let h = self.marker_height;
        let a = self.project([x, y, h])?;
        let b = self.project([x + 0.02 * heading.cos(), y + 0.02 * heading.sin(), h])?;
        let yaw = (b[1] - a[1]).atan2(b[0] - a[0]).to_degrees();
        let (u, v) = (
            a[0] + self.noise_px * noise.normal(),
            a[1] + self.noise_px * noise.normal(),
        );
        Some((u * self.wire_scale, v * self.wire_scale, yaw))
    }

    /// What the tracker reports for a fiducial on the screen at `(x, y)` (our frame).
    pub fn see_fiducial(&self, x: f64, y: f64, noise: &mut Noise) -> Option<(f64, f64)> {
        let a = self.project([x, y, 0.0])?;
        let (mut u, mut v) = (
            a[0] + self.noise_px * noise.normal(),
            a[1] + self.noise_px * noise.normal(),
        );
        if noise.uniform() < self.outlier_rate {
            let angle = std::f64::consts::TAU * noise.uniform();
            let off = 5.0 + 15.0 * noise.uniform();
            u += off * angle.cos();
            v += off * angle.sin();
        }
        Some((u * self.wire_scale, v * self.wire_scale))
    }
}

fn mul(a: &[[f64; 3]; 3], b: &[[f64; 3]; 3]) -> [[f64; 3]; 3] {
    std::array::from_fn(|r| std::array::from_fn(|c| (0..3).map(|k| a[r][k] * b[k][c]).sum()))
}

/// A small deterministic noise source (splitmix64, Box-Muller).
#[derive(Clone, Debug)]
pub struct Noise(u64);

impl Noise {
    pub fn new(seed: u64) -> Noise {
        Noise(seed ^ 0x5DEE_CE66_D1CE_4E5B)
    }
    pub fn uniform(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
    pub fn normal(&mut self) -> f64 {
        let u = self.uniform().max(1e-300);
        let v = self.uniform();
        (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
    }
}

/// The centres (our frame, m) of the white discs in a calibration frame (black with white discs;
/// `size` the panel's size, m). A frame with other content (a pheromone screen) holds none: more
/// than 2% of pixels neither black nor white, or more than a fifth white.
pub fn detect_fiducials(frame: &RgbImage, size: [f64; 2]) -> Vec<[f64; 2]> {
    let (w, h) = frame.dimensions();
    let total = (w as usize) * (h as usize);
    if total == 0 {
        return Vec::new();
    }
    let mut white = vec![false; total];
    let (mut whites, mut others) = (0usize, 0usize);
    for (i, p) in frame.pixels().enumerate() {
        let (lo, hi) = (p.0.iter().min().copied(), p.0.iter().max().copied());
        if lo.unwrap_or(0) >= 200 {
            white[i] = true;
            whites += 1;
        } else if hi.unwrap_or(0) > 40 {
            others += 1;
            // A pheromone screen: known after a few rows, not the whole frame.
            if others * 50 > total {
                return Vec::new();
            }
        }
    }
    if others * 50 > total || whites * 5 > total || whites == 0 {
        return Vec::new();
    }
    let mut centres = Vec::new();
    let mut stack = Vec::new();
    for start in 0..total {
        if !white[start] {
            continue;
        }
        white[start] = false;
        stack.push(start);
        let (mut n, mut sx, mut sy) = (0usize, 0.0f64, 0.0f64);
        while let Some(i) = stack.pop() {
            let (x, y) = (i % w as usize, i / w as usize);
            n += 1;
            sx += x as f64 + 0.5;
            sy += y as f64 + 0.5;
            let mut visit = |j: usize| {
                if white[j] {
                    white[j] = false;
                    stack.push(j);
                }
            };
            if x > 0 {
                visit(i - 1);
            }
            if x + 1 < w as usize {
                visit(i + 1);
            }
            if y > 0 {
                visit(i - w as usize);
            }
            if y + 1 < h as usize {
                visit(i + w as usize);
            }
        }
        if n >= 4 {
            let (cx, cy) = (sx / n as f64, sy / n as f64);
            centres.push([cx / w as f64 * size[0], size[1] - cy / h as f64 * size[1]]);
        }
    }
    centres
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::calibrate::render_fiducials;

    #[test]
    fn the_screen_maps_to_the_image_by_a_homography() {
        let size = [1.439, 0.809];
        let cam = CameraModel::lab(size);
        let h = cam.screen_to_image([3840, 2160], size).unwrap();
        for (u, v) in [(100.0, 200.0), (3000.0, 1800.0), (1920.0, 1080.0)] {
            let m = [u / 3840.0 * size[0], size[1] - v / 2160.0 * size[1], 0.0];
            let a = cam.project(m).unwrap();
            let b = h.apply([u, v]).unwrap();
            assert!((a[0] - b[0]).abs() < 1e-6 && (a[1] - b[1]).abs() < 1e-6);
        }
        // The whole panel is in the picture.
        for c in [[0.0, 0.0], [3840.0, 2160.0]] {
            let p = h.apply(c).unwrap();
            assert!(
                p[0] > 0.0 && p[0] < 960.0 && p[1] > 0.0 && p[1] < 720.0,
                "{p:?}"
            );
        }
    }

    #[test]
    fn discs_are_found_at_their_centres() {
        let size = [1.439, 0.809];
        let centres = [[500.25, 400.5], [3000.0, 1700.75]];
        let img = render_fiducials(&centres, 50.0, [3840, 2160], 1920, 1080);
        let found = detect_fiducials(&img, size);
        assert_eq!(found.len(), 2);
        for (f, c) in found.iter().zip(&centres) {
            let m = [c[0] / 3840.0 * size[0], size[1] - c[1] / 2160.0 * size[1]];
            assert!(
                (f[0] - m[0]).abs() < 2e-4 && (f[1] - m[1]).abs() < 2e-4,
                "{f:?} {m:?}"
            );
        }
        let mut busy = img.clone();
        for p in busy.pixels_mut().step_by(7) {
            p.0 = [120, 30, 200];
        }
        assert!(detect_fiducials(&busy, size).is_empty());
    }
}
