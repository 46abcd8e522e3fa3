//! Obstacles from an image mask: solid pixels -> the fewest simple boxes (runs of a row, merged with
//! the same run in the rows below), so a maze drawn as a PNG costs a few hundred boxes, not a
//! million pixels.
use crate::channel::ImageChannel;
use crate::error::{Result, SimError};
use std::collections::HashMap;
use std::path::Path;

/// A rectangle of solid pixels in image fractions: x from the left, y from the top, `[x0, x1) x [y0, y1)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MaskRect {
    pub x0: f32,
    pub y0: f32,
    pub x1: f32,
    pub y1: f32,
}

/// The solid rectangles of the PNG at `path`: pixels whose `channel` (default luma) is at least
/// `threshold`. `pixels`, when given, is the size the image must have.
/// `key` names the image key in errors, `key_of` builds the names of its sibling keys.
pub fn solid_rects(
    key: &str,
    path: &Path,
    channel: Option<ImageChannel>,
    threshold: u8,
    pixels: Option<[u32; 2]>,
    key_of: &dyn Fn(&str) -> String,
) -> Result<Vec<MaskRect>> {
    let channel = channel.unwrap_or(ImageChannel::Luma);
    let img = image::open(path)
        .map_err(|e| {
            SimError::invalid(
                key,
                format!("\"{}\"", path.display()),
                format!("cannot read the mask image: {e}"),
            )
        })?
        .to_rgba8();
    let (w, h) = img.dimensions();
    if let Some([pw, ph]) = pixels
        && (pw, ph) != (w, h)
    {
        return Err(SimError::invalid(
            key_of("pixels"),
            format!("[{pw}, {ph}]"),
            format!("the image {} is {w} x {h} pixels", path.display()),
        ));
    }
    if w == 0 || h == 0 {
        return Err(SimError::invalid(
            key,
            format!("\"{}\"", path.display()),
            "the mask image is empty",
        ));
    }
    let solid = |x: u32, y: u32| channel.pick(&img.get_pixel(x, y).0) >= threshold;
    Ok(merge_runs(w, h, solid)
        .into_iter()
        .map(|(x0, y0, x1, y1)| MaskRect {
            x0: x0 as f32 / w as f32,
            y0: y0 as f32 / h as f32,
            x1: x1 as f32 / w as f32,
            y1: y1 as f32 / h as f32,
        })
        .collect())
}

/// Pixel rectangles `(x0, y0, x1, y1)` (half-open) covering exactly the solid pixels: each row's runs,
/// a run extending the rectangle above it when that one ended on the row before with the same span.
pub fn merge_runs(w: u32, h: u32, solid: impl Fn(u32, u32) -> bool) -> Vec<(u32, u32, u32, u32)> {
    let mut done = Vec::new();
    // Open rectangles by their span (x0, x1) -> y0; they reach the row before the current one.
    let mut open: HashMap<(u32, u32), u32> = HashMap::new();
    for y in 0..h {
        let mut next = HashMap::new();
        let mut x = 0;
        while x < w {
            if !solid(x, y) {
                x += 1;
                continue;
            }
            let x0 = x;
            while x < w && solid(x, y) {
                x += 1;
            }
            let y0 = open.remove(&(x0, x)).unwrap_or(y);
            next.insert((x0, x), y0);
        }
        done.extend(open.drain().map(|((x0, x1), y0)| (x0, y0, x1, y)));
        open = next;
    }
    done.extend(open.drain().map(|((x0, x1), y0)| (x0, y0, x1, h)));
    // Hash maps drain in any order: sort, so that the obstacle parts (and everything built on them)
    // are the same every run.
    done.sort_unstable();
    done
}
