//! Screen <-> camera calibration: fiducials shown at known pixels, where the tracker saw them, a
//! robust homography fit, the parallax of the markers' height, the heading's sign and offset from a
//! robot driven straight; stored in a file the bridge loads.
use super::{CalibrationError, utc_now};
use crate::geometry::{Homography, fit_ransac, residual};
use crate::geometry::{ScreenMap, wrap_pi};
use image::{Rgb, RgbImage};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// What a screen calibration file holds (JSON).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ScreenCalibration {
    /// When it was measured, UTC (RFC 3339).
    pub date: String,
    /// The panel's pixels (width, height) it was measured on: a scenario with another is refused.
    pub resolution: [u32; 2],
    /// The panel's size, m.
    pub size: [f64; 2],
    /// Tracker (x, y) as on the wire -> screen pixels (origin top-left).
    pub homography: Homography,
    /// Root mean square reprojection error of the fiducials kept, mm on the screen.
    pub rms_mm: f64,
    /// The largest reprojection error kept, mm.
    pub max_mm: f64,
    /// Fiducials shown and fiducials kept by the outlier rejection.
    pub fiducials: usize,
    pub inliers: usize,
    /// Camera and marker heights above the screen, m, and the screen point under the camera (our
    /// frame, m): the parallax correction.
    pub camera_height: f64,
    pub marker_height: f64,
    pub nadir: [f64; 2],
    /// Our heading = sign * (-yaw) + offset (yaw as the tracker reports it, image axes).
    pub heading_sign: f64,
    pub heading_offset_deg: f64,
    /// Spread of the heading fit, degrees (0 when no robot was driven).
    pub heading_rms_deg: f64,
}

impl ScreenCalibration {
    pub fn map(&self) -> ScreenMap {
        ScreenMap {
            homography: self.homography,
            resolution: self.resolution,
            size: self.size,
            camera_height: self.camera_height,
            marker_height: self.marker_height,
            nadir: self.nadir,
            heading_sign: self.heading_sign,
            heading_offset: self.heading_offset_deg.to_radians(),
        }
    }

    pub fn save(&self, path: &Path) -> Result<(), CalibrationError> {
        let text =
            serde_json::to_string_pretty(self).map_err(|e| CalibrationError::file(path, e))?;
        std::fs::write(path, text + "\n").map_err(|e| CalibrationError::file(path, e))
    }

    /// Reads a calibration file and checks that it is one a bridge can apply.
    pub fn load(path: &Path) -> Result<ScreenCalibration, CalibrationError> {
        let text = std::fs::read_to_string(path).map_err(|e| CalibrationError::file(path, e))?;
        let cal: ScreenCalibration =
            serde_json::from_str(&text).map_err(|e| CalibrationError::file(path, e))?;
        let bad = |key: &str, value: String, why: &str| {
            Err(CalibrationError::Invalid {
                path: path.display().to_string(),
                key: key.into(),
                value,
                reason: why.into(),
            })
        };
        if cal.resolution.contains(&0) {
            return bad("resolution", format!("{:?}", cal.resolution), "must be > 0");
        }
        if !cal.size.iter().all(|s| s.is_finite() && *s > 0.0) {
            return bad("size", format!("{:?}", cal.size), "must be > 0 m");
        }
        if !cal.homography.is_finite() || cal.homography.inverse().is_none() {
            return bad(
                "homography",
                format!("{:?}", cal.homography.0),
                "must be finite and invertible",
            );
        }
        if !(cal.camera_height.is_finite()
            && cal.marker_height.is_finite()
            && cal.marker_height >= 0.0
            && cal.camera_height > cal.marker_height)
        {
            return bad(
                "camera_height",
                format!(
                    "{} (marker_height {})",
                    cal.camera_height, cal.marker_height
                ),
                "the camera must be above the markers, the markers at or above the screen",
            );
        }
        if cal.heading_sign.abs() != 1.0 || !cal.heading_offset_deg.is_finite() {
            return bad(
                "heading_sign",
                format!("{} (offset {})", cal.heading_sign, cal.heading_offset_deg),
                "the sign must be 1 or -1 and the offset finite",
            );
        }
        Ok(cal)
    }

    /// Refuses a calibration measured on a panel of another resolution or size than `resolution`
    /// and `size` (the scenario's `[screen]`).
    pub fn check_screen(
        &self,
        resolution: [u32; 2],
        size: [f64; 2],
    ) -> Result<(), CalibrationError> {
        if self.resolution != resolution {
            return Err(CalibrationError::WrongScreen(format!(
                "the calibration was measured at {}x{} px, the scenario's screen.resolution is {}x{}: calibrate this screen again",
                self.resolution[0], self.resolution[1], resolution[0], resolution[1]
            )));
        }
        if (0..2).any(|k| (self.size[k] - size[k]).abs() > 1e-3) {
            return Err(CalibrationError::WrongScreen(format!(
                "the calibration was measured on a {:?} m panel, the scenario's screen.size is {:?} m",
                self.size, size
            )));
        }
        Ok(())
    }
}

/// Where the fiducials go, screen pixels (centres): the four SwarmCon calibration corners inset by
/// the robot radius, then a `grid` (columns, rows) over the same inset rectangle.
pub(crate) fn fiducial_layout(
    resolution: [u32; 2],
    size: [f64; 2],
    inset: f64,
    grid: [usize; 2],
) -> Vec<[f64; 2]> {
    let px = |m: f64, k: usize| m * resolution[k] as f64 / size[k];
    let (x0, y0) = (px(inset, 0), px(inset, 1));
    let (x1, y1) = (resolution[0] as f64 - x0, resolution[1] as f64 - y0);
    let mut points = vec![[x0, y0], [x1, y0], [x1, y1], [x0, y1]];
    let [nx, ny] = grid;
    for j in 0..ny {
        for i in 0..nx {
            let fx = (i as f64 + 0.5) / nx as f64;
            let fy = (j as f64 + 0.5) / ny as f64;
            points.push([x0 + fx * (x1 - x0), y0 + fy * (y1 - y0)]);
        }
    }
    points
}

/// A black frame `width` x `height` px of a `resolution` panel with a white disc of `radius_px`
/// screen pixels at each of `centres` (screen pixels).
pub(crate) fn render_fiducials(
    centres: &[[f64; 2]],
    radius_px: f64,
    resolution: [u32; 2],
    width: u32,
    height: u32,
) -> RgbImage {
    let mut img = RgbImage::new(width, height);
    let sx = width as f64 / resolution[0] as f64;
    let sy = height as f64 / resolution[1] as f64;
    for c in centres {
        let (cx, cy, r) = (c[0] * sx, c[1] * sy, radius_px * sx);
        let (x0, x1) = ((cx - r).floor().max(0.0), (cx + r).ceil().min(width as f64));
        let (y0, y1) = (
            (cy - r).floor().max(0.0),
            (cy + r).ceil().min(height as f64),
        );
        for y in y0 as u32..y1 as u32 {
            for x in x0 as u32..x1 as u32 {
                let (dx, dy) = (x as f64 + 0.5 - cx, y as f64 + 0.5 - cy);
                if dx * dx + dy * dy <= r * r {
                    img.put_pixel(x, y, Rgb([255, 255, 255]));
                }
            }
        }
    }
    img
}

/// One fiducial: where it was shown and where the tracker saw it.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct FiducialSighting {
    /// Screen pixels.
    pub shown: [f64; 2],
    /// Tracker (x, y) as on the wire.
    pub seen: [f64; 2],
}

/// What the fit needs besides the sightings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct ScreenFitOptions {
    pub resolution: [u32; 2],
    pub size: [f64; 2],
    /// Residuals above this, mm on the screen, mark a sighting as an outlier.
    pub threshold_mm: f64,
    pub camera_height: f64,
    pub marker_height: f64,
    /// The screen point under the camera, our frame, m (the panel's centre for a centred camera).
    pub nadir: [f64; 2],
}

/// The homography from the sightings (RANSAC, then a least-squares refit on the inliers), with its
/// reprojection error in mm; the heading is left at the plain conversion (sign 1, offset 0) until
/// [`fit_heading`] sets it.
pub(crate) fn fit_screen(
    sightings: &[FiducialSighting],
    opts: &ScreenFitOptions,
) -> Result<ScreenCalibration, CalibrationError> {
    if sightings.len() < 6 {
        return Err(CalibrationError::Fit(format!(
            "{} fiducials seen: at least 6 are needed (4 corners and a grid)",
            sightings.len()
        )));
    }
    let mm_per_px = 1e3 * opts.size[0] / opts.resolution[0] as f64;
    let from: Vec<_> = sightings.iter().map(|s| s.seen).collect();
    let to: Vec<_> = sightings.iter().map(|s| s.shown).collect();
    let fit = fit_ransac(&from, &to, opts.threshold_mm / mm_per_px, 500, 17).ok_or_else(|| {
        CalibrationError::Fit(
            "the fiducials do not determine a homography (too few agree, or they lie on a line)"
                .into(),
        )
    })?;
    let inliers = fit.inliers.iter().filter(|&&k| k).count();
    if inliers * 4 < sightings.len() * 3 {
        return Err(CalibrationError::Fit(format!(
            "only {inliers} of {} fiducials agree within {} mm: is the camera seeing the screen?",
            sightings.len(),
            opts.threshold_mm
        )));
    }
    let max_px = (0..sightings.len())
        .filter(|&i| fit.inliers[i])
        .map(|i| residual(&fit.homography, from[i], to[i]))
        .fold(0.0, f64::max);
    Ok(ScreenCalibration {
        date: utc_now(),
        resolution: opts.resolution,
        size: opts.size,
        homography: fit.homography,
        rms_mm: fit.rms * mm_per_px,
        max_mm: max_px * mm_per_px,
        fiducials: sightings.len(),
        inliers,
        camera_height: opts.camera_height,
        marker_height: opts.marker_height,
        nadir: opts.nadir,
        heading_sign: 1.0,
        heading_offset_deg: 0.0,
        heading_rms_deg: 0.0,
    })
}

/// The heading's sign and offset from a robot driven straight forward in two directions (straight,
/// a turn in place, straight again: one direction cannot tell the sign): `track` holds its tracker
/// readings in order (x, y, yaw_deg as on the wire); the direction of motion, through `map`, is the
/// robot's heading wherever the yaw holds still. Returns (sign, offset rad, rms rad).
pub(crate) fn fit_heading(
    map: &ScreenMap,
    track: &[(f64, f64, f64)],
) -> Result<(f64, f64, f64), CalibrationError> {
    let poses: Vec<_> = track
        .iter()
        .filter_map(|&(x, y, yaw)| map.to_sim(x, y, yaw).map(|(px, py, _)| (px, py, yaw)))
        .collect();
    // Pairs at least 2 cm apart along the track: their direction is the heading.
    let mut pairs = Vec::new();
    let mut j = 0;
    for (i, a) in poses.iter().enumerate() {
        j = j.max(i + 1);
        while j < poses.len() && (poses[j].0 - a.0).hypot(poses[j].1 - a.1) < 0.02 {
            j += 1;
        }
        let Some(b) = poses.get(j) else { break };
        if wrap_pi((a.2 - b.2).to_radians()).abs() > 3f64.to_radians() {
            continue;
        }
        let motion = (b.1 - a.1).atan2(b.0 - a.0);
        // The yaw midway through the pair, as a unit vector mean of the two.
        let (ya, yb) = (-a.2.to_radians(), -b.2.to_radians());
        let base = (ya.sin() + yb.sin()).atan2(ya.cos() + yb.cos());
        pairs.push((motion, base));
    }
    if pairs.len() < 5 {
        return Err(CalibrationError::Fit(format!(
            "the robot driven straight moved too little ({} readings, {} pairs 2 cm apart): drive it further",
            poses.len(),
            pairs.len()
        )));
    }
    let spread = pairs
        .iter()
        .map(|p| wrap_pi(p.1 - pairs[0].1).abs())
        .fold(0.0, f64::max);
    if spread < 20f64.to_radians() {
        return Err(CalibrationError::Fit(format!(
            "the robot drove in one direction only (yaw spread {:.1} deg): the sign needs two, 20 deg or more apart",
            spread.to_degrees()
        )));
    }
    let fit = |sign: f64| {
        let (s, c) = pairs.iter().fold((0.0, 0.0), |(s, c), (m, b)| {
            let d = m - sign * b;
            (s + d.sin(), c + d.cos())
        });
        let offset = s.atan2(c);
        let ss: f64 = pairs
            .iter()
            .map(|(m, b)| wrap_pi(m - sign * b - offset).powi(2))
            .sum();
        (sign, offset, (ss / pairs.len() as f64).sqrt())
    };
    let (plus, minus) = (fit(1.0), fit(-1.0));
    Ok(if plus.2 <= minus.2 { plus } else { minus })
}
