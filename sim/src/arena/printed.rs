//! Printed obstacles (`kind = "printed"`): shapes the LCD draws in a colour on top of the pheromones,
//! as a lab prints a track or a no-go zone on the screen. The robots' colour sensors see them; nothing
//! collides with them and the bumpers do not see them. Later entries of `[[obstacles]]` draw over
//! earlier ones.
use super::Obstacles;
use crate::screen::ScreenSpec;
use glam::Vec2;
use image::RgbImage;
use std::sync::Mutex;

/// Runs of one image row to fill: (row, first column, end column, colour).
type Runs = Vec<(u32, u32, u32, [u8; 3])>;

#[derive(Default)]
pub struct Printed {
    /// The printed shapes, in their own grid (not the physical obstacles').
    pub(super) layer: Obstacles,
    /// Colour of each `[[obstacles]]` entry (by index; unused for physical ones).
    pub(super) colours: Vec<[u8; 3]>,
    /// The pixels to fill for the last image size painted: drawn every frame, computed once.
    raster: Mutex<Option<((u32, u32), Runs)>>,
}

impl Printed {
    /// The colour the screen shows at `p` (the centre of the pixel under it) if a printed obstacle
    /// covers it: the last listed of those that do.
    #[inline]
    pub fn colour_at(&self, screen: &ScreenSpec, p: Vec2) -> Option<[u8; 3]> {
        let q = screen.pixel_centre(p);
        let mut top: Option<u32> = None;
        self.layer.for_each_near(q, q, |part| {
            if top.is_none_or(|t| part.obstacle > t) && part.shape.contains_point(&part.pose, q) {
                top = Some(part.obstacle);
            }
        });
        top.and_then(|i| self.colours.get(i as usize).copied())
    }

    /// Fills the printed obstacles into `img`, a picture of the whole screen (any size).
    pub fn paint(&self, img: &mut RgbImage, screen: &ScreenSpec) {
        let size = (img.width(), img.height());
        let mut cache = self.raster.lock().unwrap_or_else(|e| e.into_inner());
        if cache.as_ref().is_none_or(|(s, _)| *s != size) {
            *cache = Some((size, self.runs(size, screen)));
        }
        let Some((_, runs)) = cache.as_ref() else {
            return;
        };
        for &(y, x0, x1, c) in runs {
            for x in x0..x1 {
                img.put_pixel(x, y, image::Rgb(c));
            }
        }
    }

    /// The pixels (centres) of a `w x h` picture of the screen each part covers, in drawing order.
    fn runs(&self, (w, h): (u32, u32), screen: &ScreenSpec) -> Runs {
        let (sx, sy) = (
            screen.size[0] / w.max(1) as f32,
            screen.size[1] / h.max(1) as f32,
        );
        let mut runs = Runs::new();
        // Parts in obstacle order, so that later entries draw over earlier ones.
        let mut parts: Vec<_> = self.layer.parts().iter().collect();
        parts.sort_by_key(|p| p.obstacle);
        for part in parts {
            let Some(&c) = self.colours.get(part.obstacle as usize) else {
                continue;
            };
            let col = |x: f32| ((x / sx).max(0.0) as u32).min(w);
            // Row 0 is the top of the screen (y = height).
            let row = |y: f32| (((screen.size[1] - y) / sy).max(0.0) as u32).min(h);
            let (x0, x1) = (col(part.lo.x), (col(part.hi.x) + 1).min(w));
            let (y0, y1) = (row(part.hi.y), (row(part.lo.y) + 1).min(h));
            for y in y0..y1 {
                let cy = screen.size[1] - (y as f32 + 0.5) * sy;
                let mut start = None;
                for x in x0..=x1 {
                    let inside = x < x1
                        && part
                            .shape
                            .contains_point(&part.pose, Vec2::new((x as f32 + 0.5) * sx, cy));
                    match (inside, start) {
                        (true, None) => start = Some(x),
                        (false, Some(s)) => {
                            runs.push((y, s, x, c));
                            start = None;
                        }
                        _ => {}
                    }
                }
            }
        }
        runs
    }
}
