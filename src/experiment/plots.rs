//! The figures: bar charts of arrivals (Fig. 5), trajectories over the screen (Fig. 6), snapshots of
//! case II (Fig. 7), S(t) with its phases (Fig. 8). Drawn with plotters into memory and saved with the
//! `image` crate; text uses a font compiled into the binary, so no system font is needed.
use super::case1::{Case1Result, preload_steady_state};
use super::case2::{Case2Result, role_colour};
use anyhow::{Result, anyhow};
use colcos_sim::behaviour::WheelCommand;
use colcos_sim::metrics::PhaseKind;
use colcos_sim::output::draw;
use colcos_sim::prelude::*;
use colcos_sim::screen;
use image::{Rgb, RgbImage};
use plotters::prelude::*;
use plotters::style::FontStyle;
use std::path::Path;

static FONT: &[u8] = include_bytes!("assets/DejaVuSans-subset.ttf");

fn ensure_font() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, FONT);
    });
}

fn err<E: std::fmt::Debug>(e: E) -> anyhow::Error {
    anyhow!("drawing: {e:?}")
}

fn save(img: &RgbImage, path: &Path) -> Result<()> {
    screen::save_png(img, path)?;
    Ok(())
}

/// Text on an image, top-left at `(x, y)` pixels.
pub fn label(
    img: &mut RgbImage,
    text: &str,
    x: i32,
    y: i32,
    size: f64,
    colour: RGBColor,
) -> Result<()> {
    ensure_font();
    let (w, h) = img.dimensions();
    let buf: &mut [u8] = &mut *img;
    let root = BitMapBackend::with_buffer(buf, (w, h)).into_drawing_area();
    root.draw_text(
        text,
        &("sans-serif", size).into_font().color(&colour),
        (x, y),
    )
    .map_err(err)?;
    root.present().map_err(err)?;
    Ok(())
}

/// Text with a dark box behind it (readable over any screen colour).
pub fn boxed_label(
    img: &mut RgbImage,
    text: &str,
    x: i32,
    y: i32,
    size: f64,
    colour: RGBColor,
) -> Result<()> {
    let wpx = (text.chars().count() as f64 * size * 0.58) as i32 + 6;
    let hpx = (size * 1.25) as i32;
    for yy in y.max(0)..(y + hpx).min(img.height() as i32) {
        for xx in x.max(0)..(x + wpx).min(img.width() as i32) {
            let p = img.get_pixel_mut(xx as u32, yy as u32);
            p.0 = p.0.map(|c| c / 4);
        }
    }
    label(img, text, x + 3, y + 1, size, colour)
}

/// The screen of case-I group `g` (its steady-state trails) at `width` pixels.
pub fn case1_screen(r: &Case1Result, g: usize, width: u32) -> Result<RgbImage> {
    let sc = r.config.scenario(g)?;
    let mut world = World::new(&sc)?;
    preload_steady_state(&mut world);
    world.step_with_commands(&[WheelCommand::STOP]);
    let s = *world.screen();
    let height = (width as f32 * s.size[1] / s.size[0]).round() as u32;
    Ok(screen::render(world.pheromones(), &s, width, height))
}

fn thick_path(img: &mut RgbImage, s: &screen::ScreenSpec, pts: &[Vec2], c: Rgb<u8>) {
    let (w, h) = (img.width(), img.height());
    for pair in pts.windows(2) {
        let a = draw::to_pixel(s, w, h, pair[0]);
        let b = draw::to_pixel(s, w, h, pair[1]);
        for (dx, dy) in [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0)] {
            draw::line(img, (a.0 + dx, a.1 + dy), (b.0 + dx, b.1 + dy), c);
        }
    }
}

/// Numbers the end points (food points in orange) and marks the nest.
fn annotate_layout(img: &mut RgbImage, r: &Case1Result, size: f64) -> Result<()> {
    let s = screen::ScreenSpec {
        size: super::layout::SCREEN,
        ..Default::default()
    };
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
            -(size as i32) * (text.len() as i32) * 6 / 10 - 14
        } else {
            12
        };
        boxed_label(
            img,
            &text,
            x as i32 + dx,
            y as i32 - (size as i32) / 2,
            size,
            colour,
        )?;
    }
    let (x, y) = draw::to_pixel(&s, w, h, lay.nest().pos);
    draw::disc(img, (x, y), (size * 0.35) as f32, Rgb([255, 255, 255]));
    boxed_label(
        img,
        "nest",
        x as i32 - (size as i32),
        y as i32 + (size as i32) / 2,
        size,
        WHITE,
    )?;
    Ok(())
}

/// Fig. 6: the trajectories of group `g` drawn over its screen image.
pub fn fig6_trajectories(r: &Case1Result, g: usize, path: &Path) -> Result<()> {
    let mut img = trajectories_panel(r, g, 1440)?;
    let grp = &r.groups[g];
    let title = format!(
        "Case I, {} ({}): {} trajectories, layout {}, food {:?}",
        grp.name,
        grp.pheromones.join(" + "),
        grp.trials.len(),
        r.config.layout.name,
        r.config.foods
    );
    boxed_label(&mut img, &title, 10, 8, 26.0, WHITE)?;
    save(&img, path)
}

fn trajectories_panel(r: &Case1Result, g: usize, width: u32) -> Result<RgbImage> {
    let mut img = case1_screen(r, g, width)?;
    let s = screen::ScreenSpec {
        size: super::layout::SCREEN,
        ..Default::default()
    };
    let palette = [
        Rgb([255, 255, 255]),
        Rgb([255, 230, 80]),
        Rgb([255, 140, 200]),
        Rgb([180, 255, 120]),
    ];
    for (t, trial) in r.groups[g].trials.iter().enumerate() {
        thick_path(&mut img, &s, &trial.path, palette[t % palette.len()]);
    }
    annotate_layout(&mut img, r, (width as f64 / 60.0).max(12.0))?;
    Ok(img)
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
        boxed_label(
            &mut img,
            &format!("{} ({})", g.name, g.pheromones.join(" + ")),
            8,
            (k as u32 * (h + gap)) as i32 + 6,
            22.0,
            WHITE,
        )?;
    }
    save(&img, path)
}

/// Fig. 5: arrivals per end point, one bar panel per group, available food marked with orange stars.
pub fn fig5_arrivals(r: &Case1Result, path: &Path) -> Result<()> {
    ensure_font();
    let (w, h) = (1200u32, 1050u32);
    let mut buf = vec![255u8; (w * h * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        let (top, rest) = root.split_vertically(50);
        top.draw_text(
            &format!(
                "Case I: arrivals per end point, {} trials per group, layout {}, food {:?} (stars)",
                r.config.trials, r.config.layout.name, r.config.foods
            ),
            &("sans-serif", 24).into_font().color(&BLACK),
            (20, 14),
        )
        .map_err(err)?;
        let n = r.config.layout.ends.len();
        let ymax = r
            .groups
            .iter()
            .map(|g| g.counts.max_at_one_point())
            .max()
            .unwrap_or(1)
            .max(r.config.trials.min(20)) as f64
            * 1.15;
        let panels = rest.split_evenly((r.groups.len(), 1));
        for (g, area) in r.groups.iter().zip(panels) {
            let at_food = g.at_food(&r.config.foods);
            let caption = format!(
                "{} ({}): {} of {} at food, {} timeouts",
                g.name,
                g.pheromones.join(" + "),
                at_food,
                g.trials.len(),
                g.counts.timeouts
            );
            let mut chart = ChartBuilder::on(&area)
                .caption(caption, ("sans-serif", 22))
                .margin(10)
                .x_label_area_size(40)
                .y_label_area_size(50)
                .build_cartesian_2d(0.5f64..(n as f64 + 0.5), 0f64..ymax)
                .map_err(err)?;
            chart
                .configure_mesh()
                .disable_x_mesh()
                .x_labels(n)
                .x_label_formatter(&|x| format!("{}", x.round() as i64))
                .x_desc("end point")
                .y_desc("arrivals")
                .label_style(("sans-serif", 16))
                .axis_desc_style(("sans-serif", 18))
                .draw()
                .map_err(err)?;
            let bar = RGBColor(70, 110, 200);
            chart
                .draw_series(g.counts.per_point.iter().enumerate().map(|(k, &c)| {
                    let x = (k + 1) as f64;
                    Rectangle::new([(x - 0.35, 0.0), (x + 0.35, c as f64)], bar.filled())
                }))
                .map_err(err)?;
            chart
                .draw_series(
                    g.counts
                        .per_point
                        .iter()
                        .enumerate()
                        .filter(|(_, c)| **c > 0)
                        .map(|(k, &c)| {
                            Text::new(
                                format!("{c}"),
                                ((k + 1) as f64 - 0.12, c as f64 + ymax * 0.09),
                                ("sans-serif", 16).into_font(),
                            )
                        }),
                )
                .map_err(err)?;
            let orange = RGBColor(255, 140, 0);
            chart
                .draw_series(r.config.foods.iter().map(|&f| {
                    let c = g.counts.per_point.get(f - 1).copied().unwrap_or(0) as f64;
                    EmptyElement::at((f as f64, c + ymax * 0.16))
                        + Polygon::new(star(11.0), orange.filled())
                }))
                .map_err(err)?;
        }
        root.present().map_err(err)?;
    }
    let img = RgbImage::from_raw(w, h, buf).ok_or_else(|| anyhow!("image buffer"))?;
    save(&img, path)
}

/// A five-pointed star of outer radius `r` pixels around (0, 0).
fn star(r: f64) -> Vec<(i32, i32)> {
    (0..10)
        .map(|k| {
            let a = -std::f64::consts::FRAC_PI_2 + k as f64 * std::f64::consts::PI / 5.0;
            let rr = if k % 2 == 0 { r } else { 0.45 * r };
            ((rr * a.cos()).round() as i32, (rr * a.sin()).round() as i32)
        })
        .collect()
}

const AGG: RGBColor = RGBColor(200, 235, 200);
const DISP: RGBColor = RGBColor(250, 205, 205);

/// Fig. 8: S(t) of the first run with its phases coloured (other runs in grey).
pub fn fig8_s_t(r: &Case2Result, path: &Path) -> Result<()> {
    ensure_font();
    let (w, h) = (1200u32, 600u32);
    let mut buf = vec![255u8; (w * h * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        let run = &r.runs[0];
        let tmax = run.times.last().copied().unwrap_or(1.0) as f64;
        let smax = r
            .runs
            .iter()
            .flat_map(|x| x.s.iter())
            .copied()
            .fold(0.0f32, f32::max) as f64
            * 1.08;
        let mut chart = ChartBuilder::on(&root)
            .caption(
                "Case II: S(t), eq. (9): sum of follower-leader distances",
                ("sans-serif", 24),
            )
            .margin(15)
            .x_label_area_size(45)
            .y_label_area_size(60)
            .build_cartesian_2d(0f64..tmax, 0f64..smax.max(0.1))
            .map_err(err)?;
        chart
            .draw_series(run.phases.iter().map(|p| {
                let c = if p.kind == PhaseKind::Aggregation {
                    AGG
                } else {
                    DISP
                };
                Rectangle::new([(p.start as f64, 0.0), (p.end as f64, smax)], c.filled())
            }))
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_desc("time (s)")
            .y_desc("S (m)")
            .label_style(("sans-serif", 16))
            .axis_desc_style(("sans-serif", 18))
            .light_line_style(RGBColor(230, 230, 230))
            .draw()
            .map_err(err)?;
        for (k, other) in r.runs.iter().enumerate().skip(1) {
            let s = chart
                .draw_series(LineSeries::new(
                    other
                        .times
                        .iter()
                        .zip(&other.s)
                        .map(|(&t, &s)| (t as f64, s as f64)),
                    RGBColor(150, 150, 150).stroke_width(1),
                ))
                .map_err(err)?;
            if k == 1 {
                s.label("other runs").legend(|(x, y)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], RGBColor(150, 150, 150))
                });
            }
        }
        chart
            .draw_series(LineSeries::new(
                run.times
                    .iter()
                    .zip(&run.s)
                    .map(|(&t, &s)| (t as f64, s as f64)),
                BLACK.stroke_width(3),
            ))
            .map_err(err)?
            .label("S(t), run 0")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLACK.stroke_width(3)));
        chart
            .draw_series(std::iter::once(Rectangle::new(
                [(0.0, 0.0), (0.0, 0.0)],
                AGG.filled(),
            )))
            .map_err(err)?
            .label("aggregation")
            .legend(|(x, y)| Rectangle::new([(x, y - 6), (x + 20, y + 6)], AGG.filled()));
        chart
            .draw_series(std::iter::once(Rectangle::new(
                [(0.0, 0.0), (0.0, 0.0)],
                DISP.filled(),
            )))
            .map_err(err)?
            .label("dispersion (alarm)")
            .legend(|(x, y)| Rectangle::new([(x, y - 6), (x + 20, y + 6)], DISP.filled()));
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperRight)
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .label_font(("sans-serif", 16))
            .draw()
            .map_err(err)?;
        root.present().map_err(err)?;
    }
    let img = RgbImage::from_raw(w, h, buf).ok_or_else(|| anyhow!("image buffer"))?;
    save(&img, path)
}

/// The times Fig. 7 shows: the start, the end of the first aggregation, and a few moments of the first
/// dispersion and after it.
fn snapshot_times(r: &Case2Result) -> Vec<f32> {
    let run = &r.runs[0];
    let end = run.times.last().copied().unwrap_or(0.0);
    let mut t = vec![0.0];
    match run
        .phases
        .iter()
        .position(|p| p.kind == PhaseKind::Dispersion)
    {
        Some(k) => {
            let d = run.phases[k];
            t.push(0.5 * d.start);
            t.push(d.start);
            t.push(d.start + 0.5 * (d.end - d.start));
            t.push(d.end);
            t.push(end.min(d.end + 0.5 * (end - d.end)).max(d.end));
        }
        None => t.extend([0.2, 0.4, 0.6, 0.8, 1.0].map(|f| f * end)),
    }
    t
}

/// Fig. 7: a strip of six screen snapshots of the first run (nearest snapshot to each chosen time).
pub fn fig7_snapshots(r: &Case2Result, path: &Path) -> Result<()> {
    let run = &r.runs[0];
    if run.snapshots.is_empty() {
        return Err(anyhow!("no snapshots were taken"));
    }
    let picks: Vec<&(f32, RgbImage)> = snapshot_times(r)
        .into_iter()
        .map(|t| {
            run.snapshots
                .iter()
                .min_by(|a, b| (a.0 - t).abs().total_cmp(&(b.0 - t).abs()))
                .expect("non-empty")
        })
        .collect();
    let (w, h) = (picks[0].1.width(), picks[0].1.height());
    let (cols, gap) = (3u32, 8u32);
    let rows = (picks.len() as u32).div_ceil(cols);
    let mut img = RgbImage::from_pixel(
        cols * w + (cols + 1) * gap,
        rows * h + (rows + 1) * gap + 40,
        Rgb([255, 255, 255]),
    );
    label(
        &mut img,
        "Case II snapshots (run 0): AGP green around the leader (yellow), ALP red; predator white",
        10,
        8,
        20.0,
        BLACK,
    )?;
    for (k, (t, snap)) in picks.iter().enumerate() {
        let (c, rr) = (k as u32 % cols, k as u32 / cols);
        let (x, y) = (gap + c * (w + gap), 40 + gap + rr * (h + gap));
        image::imageops::replace(&mut img, snap, x as i64, y as i64);
        let j = run.times.iter().position(|&u| u >= *t - 1e-3).unwrap_or(0);
        let phase = if run.alarm.get(j).copied().unwrap_or(false) {
            "dispersion"
        } else {
            "aggregation"
        };
        boxed_label(
            &mut img,
            &format!("({}) t = {:.0} s, {}", k + 1, t, phase),
            x as i32 + 4,
            y as i32 + 4,
            16.0,
            WHITE,
        )?;
    }
    save(&img, path)
}

/// Case II trajectories of the first run, every robot in its role's colour, over a dark arena.
pub fn case2_trajectories(r: &Case2Result, path: &Path) -> Result<()> {
    let run = &r.runs[0];
    let s = r.config.scenario.spec.screen;
    let (w, h) = (1200u32, (1200.0 * s.size[1] / s.size[0]) as u32);
    let mut img = RgbImage::from_pixel(w, h, Rgb([25, 25, 35]));
    let follower_colours = [
        Rgb([90, 170, 255]),
        Rgb([120, 230, 160]),
        Rgb([200, 140, 255]),
    ];
    let mut f = 0;
    let mut legend = Vec::new();
    for (path_i, role) in run.paths.iter().zip(&run.roles) {
        let c = if role == "follower" {
            f += 1;
            follower_colours[(f - 1) % follower_colours.len()]
        } else {
            role_colour(role)
        };
        thick_path(&mut img, &s, path_i, c);
        if let (Some(a), Some(b)) = (path_i.first(), path_i.last()) {
            draw::disc(&mut img, draw::to_pixel(&s, w, h, *a), 5.0, c);
            let p = draw::to_pixel(&s, w, h, *b);
            draw::disc(&mut img, p, 8.0, c);
            draw::disc(&mut img, p, 4.0, Rgb([25, 25, 35]));
        }
        legend.push((
            if role == "follower" {
                format!("follower {f}")
            } else {
                role.clone()
            },
            c,
        ));
    }
    label(
        &mut img,
        &format!(
            "Case II trajectories, run 0, {:.0} s (small dot: start, ring: end)",
            run.times.last().copied().unwrap_or(0.0)
        ),
        10,
        8,
        20.0,
        WHITE,
    )?;
    for (k, (name, c)) in legend.iter().enumerate() {
        label(
            &mut img,
            name,
            10,
            36 + 22 * k as i32,
            18.0,
            RGBColor(c.0[0], c.0[1], c.0[2]),
        )?;
    }
    save(&img, path)
}
