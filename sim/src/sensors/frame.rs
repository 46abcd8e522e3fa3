//! Sensing a displayed frame: what a robot's colour sensors read from an RGB image of the panel, as the
//! real sensors read the LCD (a digital twin reads the frames a bridge displays).
use super::ColourSensor;
use crate::rng::SimRng;
use crate::screen::ScreenSpec;
use glam::Vec2;
use image::RgbImage;

/// The pixel of `frame` (an image of the whole panel of `size` m, row 0 at the top) that shows `p`;
/// points off the panel map to the nearest edge pixel.
pub fn frame_pixel(frame: &RgbImage, size: Vec2, p: Vec2) -> [u8; 3] {
    let spec = ScreenSpec::new([frame.width(), frame.height()], size.into());
    let c = spec.pixel_centre(p);
    let ps = spec.pixel_size();
    let col = (c.x / ps.x) as u32;
    let row_from_bottom = (c.y / ps.y) as u32;
    let row = frame.height().saturating_sub(1 + row_from_bottom);
    if frame.width() == 0 || frame.height() == 0 {
        return [0; 3];
    }
    frame.get_pixel(col.min(frame.width() - 1), row).0
}

impl ColourSensor {
    /// Counts of the sensors at `sensors` (arena coordinates) reading `frame`, an image of the whole
    /// panel of `size` m at any resolution: the mean 8-bit level over each footprint's samples, then
    /// [`ColourSensor::counts`] (transfer curve, crosstalk, gain, integration, noise), sensor by sensor.
    pub fn read_frame<const S: usize>(
        &self,
        frame: &RgbImage,
        size: Vec2,
        sensors: &[Vec2; S],
        rng: &mut SimRng,
    ) -> [[u16; 3]; S] {
        sensors.map(|p| {
            let points = self.sample_points(p);
            let mut sum = [0u32; 3];
            for q in &points {
                let px = frame_pixel(frame, size, *q);
                for c in 0..3 {
                    sum[c] += px[c] as u32;
                }
            }
            let n = points.len() as f32;
            self.counts(sum.map(|s| s as f32 / n), rng)
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sensors::ColourSensorParams;

    /// A frame whose left half is red reads red on the left and dark on the right, with the same
    /// counts as the sensor model gives for those levels.
    #[test]
    fn a_frame_reads_as_its_levels() {
        let mut frame = RgbImage::new(40, 20);
        for (x, _, px) in frame.enumerate_pixels_mut() {
            *px = image::Rgb(if x < 20 { [200, 0, 0] } else { [0, 0, 0] });
        }
        let params = ColourSensorParams {
            noise: 0.0,
            ..Default::default()
        };
        let sensor = ColourSensor::new(params);
        let size = Vec2::new(0.4, 0.2);
        let mut rng = crate::rng::stream(1, 0, 0);
        let [left, right] = sensor.read_frame(
            &frame,
            size,
            &[Vec2::new(0.1, 0.1), Vec2::new(0.3, 0.1)],
            &mut rng,
        );
        assert_eq!(left, sensor.counts([200.0, 0.0, 0.0], &mut rng));
        assert_eq!(right, sensor.counts([0.0, 0.0, 0.0], &mut rng));
        assert!(left[0] > right[0]);
        // Row 0 is the top of the panel.
        let mut top = RgbImage::new(4, 4);
        top.put_pixel(0, 0, image::Rgb([1, 2, 3]));
        assert_eq!(frame_pixel(&top, Vec2::ONE, Vec2::new(0.1, 0.9)), [1, 2, 3]);
        assert_eq!(frame_pixel(&top, Vec2::ONE, Vec2::new(0.1, 0.1)), [0, 0, 0]);
    }
}
