//! Robots drawn over a screen image (for GIFs and figures): each robot group in its own colour, and a
//! legend naming the groups.
use crate::robot::Pose;
use crate::scenario::RobotGroupSpec;
use crate::screen::ScreenSpec;
use crate::world::{ArenaView, World};
use ab_glyph::{Font, FontRef, PxScale, ScaleFont, point};
use glam::Vec2;
use image::{Rgb, RgbImage};

/// DejaVu Sans (https://dejavu-fonts.github.io/, Bitstream Vera licence with public-domain DejaVu
/// changes) cut down to printable ASCII and a few symbols with `pyftsubset`, compiled in so that
/// legends and plots need no system font. The one copy: the experiment's and the sweep's plots use it.
pub static FONT: &[u8] = include_bytes!("DejaVuSans-subset.ttf");

/// Colours of robot groups 0, 1, 2, ... (then again): light and saturated, so that they read over
/// black and over the red, green and blue of the pheromones, and differ from each other.
pub const GROUP_COLOURS: [Rgb<u8>; 8] = [
    Rgb([255, 255, 255]),
    Rgb([255, 220, 60]),
    Rgb([255, 120, 200]),
    Rgb([90, 230, 255]),
    Rgb([255, 150, 40]),
    Rgb([170, 255, 120]),
    Rgb([200, 160, 255]),
    Rgb([170, 170, 170]),
];

/// The colour of robot group `g`.
pub fn group_colour(g: usize) -> Rgb<u8> {
    GROUP_COLOURS[g % GROUP_COLOURS.len()]
}

/// Every robot's colour: its group's.
pub fn robot_colours(world: &dyn ArenaView) -> Vec<Rgb<u8>> {
    world
        .robots()
        .iter()
        .map(|r| group_colour(r.group))
        .collect()
}

/// A legend line per robot group of the world's scenario: `role: count behaviour` (`group k` where
/// the group has no role), with its colour.
pub fn group_legend(world: &World) -> Vec<(String, Rgb<u8>)> {
    groups_legend(&world.scenario().spec.robots)
}

/// [`group_legend`] of the robot groups `groups`.
pub fn groups_legend(groups: &[RobotGroupSpec]) -> Vec<(String, Rgb<u8>)> {
    groups
        .iter()
        .enumerate()
        .map(|(g, spec)| {
            let name = if spec.role.is_empty() {
                format!("group {}", g + 1)
            } else {
                spec.role.clone()
            };
            (
                format!("{name}: {} {}", spec.count, spec.behaviour),
                group_colour(g),
            )
        })
        .collect()
}

/// Blends `c` into the pixel at `(x, y)` with weight `a` in [0, 1].
fn blend(img: &mut RgbImage, x: i64, y: i64, c: Rgb<u8>, a: f32) {
    if x >= 0 && y >= 0 && (x as u32) < img.width() && (y as u32) < img.height() {
        let p = img.get_pixel_mut(x as u32, y as u32);
        for (v, cv) in p.0.iter_mut().zip(c.0) {
            *v = (*v as f32 * (1.0 - a) + cv as f32 * a).round() as u8;
        }
    }
}

/// Text `px` pixels high, its top-left corner at `(x, y)`, anti-aliased. Returns its width in pixels.
/// Characters the font lacks are skipped.
pub fn text(img: &mut RgbImage, s: &str, x: f32, y: f32, px: f32, c: Rgb<u8>) -> f32 {
    let Ok(font) = FontRef::try_from_slice(FONT) else {
        return 0.0;
    };
    let scaled = font.as_scaled(PxScale::from(px));
    let mut caret = x;
    let mut prev = None;
    for ch in s.chars() {
        let id = scaled.glyph_id(ch);
        if let Some(p) = prev {
            caret += scaled.kern(p, id);
        }
        let glyph = id.with_scale_and_position(px, point(caret, y + scaled.ascent()));
        if let Some(outline) = font.outline_glyph(glyph) {
            let b = outline.px_bounds();
            outline.draw(|gx, gy, cov| {
                blend(
                    img,
                    b.min.x as i64 + gx as i64,
                    b.min.y as i64 + gy as i64,
                    c,
                    cov.clamp(0.0, 1.0),
                );
            });
        }
        caret += scaled.h_advance(id);
        prev = Some(id);
    }
    caret - x
}

/// The width in pixels of `s` drawn by [`text`] at `px`.
pub fn text_width(s: &str, px: f32) -> f32 {
    let Ok(font) = FontRef::try_from_slice(FONT) else {
        return 0.0;
    };
    let scaled = font.as_scaled(PxScale::from(px));
    let mut w = 0.0;
    let mut prev = None;
    for ch in s.chars() {
        let id = scaled.glyph_id(ch);
        if let Some(p) = prev {
            w += scaled.kern(p, id);
        }
        w += scaled.h_advance(id);
        prev = Some(id);
    }
    w
}

/// A legend in the top-left corner: a coloured disc and a name per entry, on a darkened box. The text
/// is about a fortieth of the image's width high (at least 10 pixels).
pub fn legend(img: &mut RgbImage, entries: &[(String, Rgb<u8>)]) {
    if entries.is_empty() {
        return;
    }
    let px = (img.width() as f32 / 40.0).max(10.0);
    let line = (px * 1.3).ceil();
    let pad = (px * 0.4).ceil();
    let widest = entries
        .iter()
        .map(|(s, _)| text_width(s, px))
        .fold(0.0, f32::max);
    let (bw, bh) = (
        (pad * 3.0 + px + widest).ceil() as i64,
        (pad * 2.0 + line * entries.len() as f32).ceil() as i64,
    );
    for y in 0..bh {
        for x in 0..bw {
            blend(img, x, y, Rgb([0, 0, 0]), 0.6);
        }
    }
    for (k, (name, c)) in entries.iter().enumerate() {
        let top = pad + k as f32 * line;
        disc(img, (pad + 0.5 * px, top + 0.6 * px), 0.4 * px, *c);
        text(img, name, pad * 2.0 + px, top, px, *c);
    }
}

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

/// Every robot as a disc of its true size in its colour, with a dark rim and a dark line along its
/// heading.
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
        disc(img, c, r_px + 1.0, Rgb([20, 20, 20]));
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

/// Outline colour of physical obstacles: amber, apart from every pheromone and group colour's grey rim.
pub const OBSTACLE_OUTLINE: Rgb<u8> = Rgb([255, 176, 0]);

/// Every obstacle: a printed one filled in its colour, as the LCD shows it; a physical one as its
/// outline, as the overhead camera sees an object on the screen (the LCD under it draws nothing): a
/// closed line two pixels wide.
pub fn obstacles(img: &mut RgbImage, screen: &ScreenSpec, obstacles: &crate::arena::Obstacles) {
    if let Some(printed) = obstacles.printed() {
        printed.paint(img, screen);
    }
    let (w, h) = (img.width(), img.height());
    for (_, ring) in obstacles.outlines() {
        for k in 0..ring.len() {
            let (a, b) = (ring[k], ring[(k + 1) % ring.len()]);
            let (pa, pb) = (to_pixel(screen, w, h, a), to_pixel(screen, w, h, b));
            line(img, pa, pb, OBSTACLE_OUTLINE);
            line(
                img,
                (pa.0 + 1.0, pa.1),
                (pb.0 + 1.0, pb.1),
                OBSTACLE_OUTLINE,
            );
            line(
                img,
                (pa.0, pa.1 + 1.0),
                (pb.0, pb.1 + 1.0),
                OBSTACLE_OUTLINE,
            );
        }
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::output::gif::frame_image;
    use crate::scenario::{PheromoneSpec, RobotGroupSpec, Scenario, ScenarioBuilder};

    /// A trail pheromone, two scouts avoiding and one robot wandering, all parked; 1 s.
    fn two_groups() -> Scenario {
        ScenarioBuilder::new()
            .duration(1.0)
            .pheromone(PheromoneSpec::grid("trail", [0.0, 0.0, 255.0]).with_evaporation(10.0))
            .robots(
                RobotGroupSpec::new(2, "avoid")
                    .with_role("scout")
                    .at_poses(vec![[0.4, 0.4, 0.0], [0.6, 0.4, 0.0]]),
            )
            .robots(RobotGroupSpec::new(1, "wander").at_poses(vec![[1.0, 0.4, 90.0]]))
            .build()
            .unwrap()
    }

    fn count(img: &RgbImage, c: Rgb<u8>, x0: u32, x1: u32, y0: u32, y1: u32) -> usize {
        (y0..y1)
            .flat_map(|y| (x0..x1).map(move |x| (x, y)))
            .filter(|&(x, y)| *img.get_pixel(x, y) == c)
            .count()
    }

    #[test]
    fn each_group_has_its_colour_and_a_legend_line() {
        let world = World::new(&two_groups()).unwrap();
        assert_eq!(
            robot_colours(&world),
            [group_colour(0), group_colour(0), group_colour(1)]
        );
        assert_ne!(group_colour(0), group_colour(1));
        let legend = group_legend(&world);
        assert_eq!(legend[0].0, "scout: 2 avoid");
        assert_eq!(legend[1].0, "group 2: 1 wander");

        let (w, h) = (480, 270);
        let img = frame_image(&world, w, h);
        let s = world.screen();
        // Each robot's centre shows its group's colour.
        for (pose, c) in world.poses().iter().zip(robot_colours(&world)) {
            let (x, y) = to_pixel(s, w, h, pose.pos);
            let px = img.get_pixel(x as u32 + 2, y as u32 + 2);
            assert_eq!(*px, c, "robot at {:?}", pose.pos);
        }
        // The legend in the top-left corner draws a disc of each group's colour, one line each.
        let line = (12.0f32 * 1.3).ceil() as u32;
        for (k, (_, c)) in legend.iter().enumerate() {
            let top = 5 + k as u32 * line;
            assert!(
                count(&img, *c, 0, 20, top, top + line) > 10,
                "legend disc {k}"
            );
        }
        // The legend's text is written in the group's colour (yellow: red and green, little blue),
        // right of the disc, over the darkened box.
        let yellowish = (20..200)
            .flat_map(|x| (5 + line..5 + 2 * line).map(move |y| (x, y)))
            .filter(|&(x, y)| {
                let p = img.get_pixel(x, y).0;
                p[0] > 120 && p[1] > 100 && (p[2] as u32) * 2 < p[0] as u32
            })
            .count();
        assert_eq!(group_colour(1), Rgb([255, 220, 60]));
        assert!(yellowish > 20, "{yellowish} text pixels");
    }

    #[test]
    fn text_has_a_width_and_draws_within_it() {
        let mut img = RgbImage::new(200, 40);
        let w = text(
            &mut img,
            "scout: 4 follow",
            5.0,
            5.0,
            16.0,
            Rgb([255, 0, 0]),
        );
        assert!((w - text_width("scout: 4 follow", 16.0)).abs() < 1e-3);
        assert!(w > 60.0 && w < 190.0, "{w}");
        let lit: Vec<u32> = img
            .enumerate_pixels()
            .filter(|(_, _, p)| p.0[0] > 0)
            .map(|(x, _, _)| x)
            .collect();
        assert!(lit.len() > 50);
        assert!(lit.iter().all(|&x| x >= 5 && (x as f32) <= 6.0 + w));
    }
}
