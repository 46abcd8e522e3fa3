//! Fig. 6: the trajectories of case I over the screen of their group. Every trial is drawn
//! half-transparent and shifted by up to 6 pixels (4 mm) (in the drawing only), so paths that share a trail
//! show as a denser bundle rather than one line; the end points are numbered and a bar gives the scale.
use super::case1::{Case1Result, freeze_steady_state};
use super::plots::{Label, save};
use anyhow::Result;
use colcos_sim::behaviour::WheelCommand;
use colcos_sim::output::draw;
use colcos_sim::prelude::*;
use colcos_sim::screen;
use image::{Rgb, RgbImage};
use plotters::style::{RGBColor, WHITE};
use std::path::Path;

/// Bright colours that read over the dimmed trails (cyan, blue, magenta) and over black.
const PALETTE: [[u8; 3]; 6] = [
    [255, 255, 255],
    [255, 225, 50],
    [255, 140, 40],
    [140, 255, 110],
    [255, 130, 210],
    [120, 200, 255],
];

/// The screen of case-I group `g` (its steady-state trails) at `width` pixels. The trail maps are
/// laid on a 5 mm grid; a blur of about half a cell hides the grid's steps in the picture.
pub fn case1_screen(r: &Case1Result, g: usize, width: u32) -> Result<RgbImage> {
    let sc = r.config.scenario(g)?;
    let mut world = World::new(&sc)?;
    freeze_steady_state(&mut world, &sc);
    world.step_with_commands(&[WheelCommand::STOP]);
    let s = *world.screen();
    let height = (width as f32 * s.size[1] / s.size[0]).round() as u32;
    let img = screen::render(world.pheromones(), &s, width, height);
    let cell_px = r.config.cell / s.size[0] * width as f32;
    Ok(image::imageops::blur(&img, 0.6 * cell_px))
}

fn layout_screen() -> screen::ScreenSpec {
    screen::ScreenSpec {
        size: super::layout::SCREEN,
        ..Default::default()
    }
}

/// Blends `c` at `alpha` into every pixel of `img` within `radius` pixels of the polyline `pts`
/// (arena points), each pixel once, shifted by `shift` pixels.
fn translucent_path(
    img: &mut RgbImage,
    pts: &[Vec2],
    shift: (f32, f32),
    radius: f32,
    c: Rgb<u8>,
    alpha: f32,
) {
    let s = layout_screen();
    let (w, h) = (img.width(), img.height());
    let mut mask = vec![false; (w * h) as usize];
    let mut stamp = |x: f32, y: f32| {
        let (x0, x1) = ((x - radius).floor() as i64, (x + radius).ceil() as i64);
        let (y0, y1) = ((y - radius).floor() as i64, (y + radius).ceil() as i64);
        for yy in y0.max(0)..=y1.min(h as i64 - 1) {
            for xx in x0.max(0)..=x1.min(w as i64 - 1) {
                let (dx, dy) = (xx as f32 + 0.5 - x, yy as f32 + 0.5 - y);
                if dx * dx + dy * dy <= radius * radius {
                    mask[yy as usize * w as usize + xx as usize] = true;
                }
            }
        }
    };
    for pair in pts.windows(2) {
        let a = draw::to_pixel(&s, w, h, pair[0]);
        let b = draw::to_pixel(&s, w, h, pair[1]);
        let n = (b.0 - a.0).abs().max((b.1 - a.1).abs()).ceil().max(1.0) as usize;
        for k in 0..=n {
            let t = k as f32 / n as f32;
            stamp(
                a.0 + t * (b.0 - a.0) + shift.0,
                a.1 + t * (b.1 - a.1) + shift.1,
            );
        }
    }
    for (p, m) in img.pixels_mut().zip(&mask) {
        if *m {
            for (v, cv) in p.0.iter_mut().zip(c.0) {
                *v = (*v as f32 * (1.0 - alpha) + cv as f32 * alpha).round() as u8;
            }
        }
    }
}

/// Numbers the end points (food points in orange) and marks the nest.
fn annotate_layout(img: &mut RgbImage, r: &Case1Result, size: f64) -> Result<()> {
    let s = layout_screen();
    let (w, h) = (img.width(), img.height());
    let lay = &r.config.layout;
    let mirror = lay.nest().pos.x > 0.5 * lay.arena.x;
    for (k, p) in lay.end_points().iter().enumerate() {
        let (x, y) = draw::to_pixel(&s, w, h, *p);
        let food = r.config.foods.contains(&(k + 1));
        let colour = if food { RGBColor(255, 165, 0) } else { WHITE };
        let text = if food {
            format!("{} food", k + 1)
        } else {
            format!("{}", k + 1)
        };
        let dx = if mirror {
            -super::plots::text_width(&text, size) - 12
        } else {
            12
        };
        Label::new(&text, size, colour).boxed(img, x as i32 + dx, y as i32 - (size as i32) / 2)?;
    }
    let (x, y) = draw::to_pixel(&s, w, h, lay.nest().pos);
    draw::disc(img, (x, y), (size * 0.35) as f32, Rgb([255, 255, 255]));
    Label::new("nest", size, WHITE).boxed(
        img,
        x as i32 - (size as i32),
        y as i32 + (size as i32) / 2,
    )?;
    Ok(())
}

/// A white bar of 10 cm with its label, in the bottom corner on the nest's side (the end points fill
/// the other side).
fn scale_bar(img: &mut RgbImage, r: &Case1Result, size: f64) -> Result<()> {
    let (w, h) = (img.width(), img.height());
    let len = (0.10 / super::layout::SCREEN[0] * w as f32).round() as u32;
    let mirror = r.config.layout.nest().pos.x > 0.5 * r.config.layout.arena.x;
    let margin = (size * 1.2) as u32;
    let x0 = if mirror { w - margin - len } else { margin };
    let y0 = h - margin;
    let white = Rgb([255, 255, 255]);
    for y in y0 - 3..=y0 + 3 {
        for x in x0..=x0 + len {
            let tick = x <= x0 + 1 || x + 1 >= x0 + len;
            if tick || (y0 - 1..=y0 + 1).contains(&y) {
                img.put_pixel(x, y, white);
            }
        }
    }
    let text = "10 cm";
    let tx = x0 as i32 + len as i32 / 2 - super::plots::text_width(text, size) / 2;
    Label::new(text, size, WHITE).draw(img, tx, (y0 as f64 - 1.6 * size) as i32)
}

/// The trajectories of group `g` over its dimmed screen, `width` pixels wide.
pub(super) fn trajectories_panel(r: &Case1Result, g: usize, width: u32) -> Result<RgbImage> {
    let mut img = case1_screen(r, g, width)?;
    for p in img.pixels_mut() {
        p.0 = p.0.map(|v| (v as f32 * 0.55) as u8);
    }
    let scale = width as f32 / 1440.0;
    let s = layout_screen();
    let (w, h) = (img.width(), img.height());
    for (t, trial) in r.groups[g].trials.iter().enumerate() {
        // Golden-angle offsets: neighbouring trials land apart, none more than 6 px (at 1440 px) off.
        let a = t as f32 * 2.399_963;
        let rad = 6.0 * scale * ((t % 4) as f32 + 1.0) / 4.0;
        let shift = (rad * a.cos(), rad * a.sin());
        let c = Rgb(PALETTE[t % PALETTE.len()]);
        translucent_path(&mut img, &trial.path, shift, 1.6 * scale.max(0.7), c, 0.6);
        if let Some(end) = trial.path.last() {
            let (x, y) = draw::to_pixel(&s, w, h, *end);
            draw::disc(&mut img, (x + shift.0, y + shift.1), 4.0 * scale, c);
        }
    }
    let size = (width as f64 / 60.0).max(12.0);
    annotate_layout(&mut img, r, size)?;
    scale_bar(&mut img, r, size)?;
    Ok(img)
}

/// Fig. 6: the trajectories of group `g` drawn over its screen image.
pub fn fig6_trajectories(r: &Case1Result, g: usize, path: &Path) -> Result<()> {
    let mut img = trajectories_panel(r, g, 1440)?;
    let grp = &r.groups[g];
    let title = format!(
        "Case I, {} ({}): {} trials, layout {}, food {:?} (one colour per trial, dot: where it ended)",
        grp.name,
        grp.pheromones.join(" + "),
        grp.trials.len(),
        r.config.layout.name,
        r.config.foods
    );
    Label::new(&title, 22.0, WHITE).boxed(&mut img, 10, 8)?;
    save(&img, path)
}

/// The trajectories of every group, one panel each, stacked.
pub fn trajectories_all_groups(r: &Case1Result, path: &Path) -> Result<()> {
    let panels: Vec<RgbImage> = (0..r.groups.len())
        .map(|g| trajectories_panel(r, g, 960))
        .collect::<Result<_>>()?;
    let (w, h) = (panels[0].width(), panels[0].height());
    let gap = 6;
    let mut img = RgbImage::from_pixel(
        w,
        (h + gap) * panels.len() as u32 - gap,
        Rgb([255, 255, 255]),
    );
    for (k, p) in panels.iter().enumerate() {
        image::imageops::replace(&mut img, p, 0, (k as u32 * (h + gap)) as i64);
        let g = &r.groups[k];
        let title = format!(
            "{} ({}), {} trials",
            g.name,
            g.pheromones.join(" + "),
            g.trials.len()
        );
        Label::new(&title, 20.0, WHITE).boxed(&mut img, 8, (k as u32 * (h + gap)) as i32 + 6)?;
    }
    save(&img, path)
}
