//! Robots drawn over a screen image (for GIFs and figures).
use crate::robot::Pose;
use crate::screen::ScreenSpec;
use glam::Vec2;
use image::{Rgb, RgbImage};

/// Pixel coordinates of arena point `p` in an image of `img_w x img_h` showing the whole screen.
pub fn to_pixel(screen: &ScreenSpec, img_w: u32, img_h: u32, p: Vec2) -> (f32, f32) {
    (
        p.x / screen.size[0] * img_w as f32,
        (1.0 - p.y / screen.size[1]) * img_h as f32,
    )
}

fn put(img: &mut RgbImage, x: i64, y: i64, c: Rgb<u8>) {
    if x >= 0 && y >= 0 && (x as u32) < img.width() && (y as u32) < img.height() {
        img.put_pixel(x as u32, y as u32, c);
    }
}

/// A line from `a` to `b` in pixel coordinates.
pub fn line(img: &mut RgbImage, a: (f32, f32), b: (f32, f32), c: Rgb<u8>) {
    let n = (b.0 - a.0).abs().max((b.1 - a.1).abs()).ceil().max(1.0) as usize;
    for k in 0..=n {
        let t = k as f32 / n as f32;
        put(
            img,
            (a.0 + t * (b.0 - a.0)).round() as i64,
            (a.1 + t * (b.1 - a.1)).round() as i64,
            c,
        );
    }
}

/// A filled disc of radius `r` pixels.
pub fn disc(img: &mut RgbImage, centre: (f32, f32), r: f32, c: Rgb<u8>) {
    let r2 = r * r;
    let (x0, x1) = ((centre.0 - r).floor() as i64, (centre.0 + r).ceil() as i64);
    let (y0, y1) = ((centre.1 - r).floor() as i64, (centre.1 + r).ceil() as i64);
    for y in y0..=y1 {
        for x in x0..=x1 {
            let (dx, dy) = (x as f32 + 0.5 - centre.0, y as f32 + 0.5 - centre.1);
            if dx * dx + dy * dy <= r2 {
                put(img, x, y, c);
            }
        }
    }
}

/// Every robot as a light disc of its true size with a dark line along its heading.
pub fn robots(
    img: &mut RgbImage,
    screen: &ScreenSpec,
    poses: &[Pose],
    radius: f32,
    colours: &[Rgb<u8>],
) {
    let (w, h) = (img.width(), img.height());
    let r_px = (radius / screen.size[0] * w as f32).max(2.0);
    for (i, p) in poses.iter().enumerate() {
        let c = to_pixel(screen, w, h, p.pos);
        disc(
            img,
            c,
            r_px,
            colours.get(i).copied().unwrap_or(Rgb([230, 230, 230])),
        );
        let tip = to_pixel(screen, w, h, p.pos + p.forward() * radius);
        line(img, c, tip, Rgb([20, 20, 20]));
    }
}

/// A polyline of arena points.
pub fn path(img: &mut RgbImage, screen: &ScreenSpec, points: &[Vec2], c: Rgb<u8>) {
    let (w, h) = (img.width(), img.height());
    for pair in points.windows(2) {
        line(
            img,
            to_pixel(screen, w, h, pair[0]),
            to_pixel(screen, w, h, pair[1]),
            c,
        );
    }
}
