//! Case II figures: Fig. 8, S(t) of the featured run with its phases (the other runs in grey); Fig. 7,
//! six moments of that run chosen from its data; and every robot's path in it. The featured run and
//! its moments come from [`super::moments`].
use super::case2::{Case2Result, role_colour, snapshots_at};
use super::moments::{featured_run, key_moments};
use super::plots::{Label, ensure_font, err, save, series_legend, text_width};
use anyhow::{Result, anyhow};
use colcos_sim::metrics::PhaseKind;
use colcos_sim::output::draw;
use image::{Rgb, RgbImage};
use plotters::prelude::*;
use std::path::Path;

const AGG: RGBColor = RGBColor(200, 235, 200);
const DISP: RGBColor = RGBColor(250, 200, 200);

/// Fig. 8: S(t) of the featured run (one with both phases) with its phases shaded, the other runs in
/// grey, and a legend above the curves.
pub fn fig8_s_t(r: &Case2Result, path: &Path) -> Result<()> {
    ensure_font();
    let (w, h) = (1200u32, 600u32);
    let mut buf = vec![255u8; (w * h * 3) as usize];
    let shown = featured_run(r);
    {
        let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        let run = &r.runs[shown];
        let tmax = run.times.last().copied().unwrap_or(1.0) as f64;
        let smax = r
            .runs
            .iter()
            .flat_map(|x| x.s.iter())
            .copied()
            .fold(0.0f32, f32::max) as f64;
        // The top quarter stays free for the legend.
        let ytop = (smax * 1.38).max(0.1);
        let mut chart = ChartBuilder::on(&root)
            .caption(
                format!(
                    "Case II: S(t) of eq. (9), the summed follower-leader distance ({} runs, seed {})",
                    r.runs.len(),
                    r.config.scenario.spec.seed
                ),
                ("sans-serif", 22),
            )
            .margin(15)
            .x_label_area_size(45)
            .y_label_area_size(60)
            .build_cartesian_2d(0f64..tmax, 0f64..ytop)
            .map_err(err)?;
        chart
            .draw_series(run.phases.iter().map(|p| {
                let c = if p.kind == PhaseKind::Aggregation {
                    AGG
                } else {
                    DISP
                };
                Rectangle::new([(p.start as f64, 0.0), (p.end as f64, ytop)], c.filled())
            }))
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_desc("time (s)")
            .y_desc("S (m)")
            .x_label_formatter(&|x| format!("{x:.0}"))
            .y_label_formatter(&|y| format!("{y:.1}"))
            .label_style(("sans-serif", 16))
            .axis_desc_style(("sans-serif", 18))
            .light_line_style(TRANSPARENT)
            .bold_line_style(RGBColor(150, 150, 150).mix(0.35))
            .draw()
            .map_err(err)?;
        let grey = RGBColor(140, 140, 140);
        let mut labelled = false;
        for (k, other) in r.runs.iter().enumerate() {
            if k == shown {
                continue;
            }
            let s = chart
                .draw_series(LineSeries::new(
                    other
                        .times
                        .iter()
                        .zip(&other.s)
                        .map(|(&t, &s)| (t as f64, s as f64)),
                    grey.stroke_width(1),
                ))
                .map_err(err)?;
            if !labelled {
                labelled = true;
                s.label("other runs")
                    .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], grey));
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
            .label(format!("S(t), run {shown}"))
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLACK.stroke_width(3)));
        for (name, c) in [
            ("aggregation phase", AGG),
            ("dispersion phase (alarm)", DISP),
        ] {
            chart
                .draw_series(std::iter::once(Rectangle::new(
                    [(0.0, 0.0), (0.0, 0.0)],
                    c.filled(),
                )))
                .map_err(err)?
                .label(name)
                .legend(move |(x, y)| Rectangle::new([(x, y - 6), (x + 20, y + 6)], c.filled()));
        }
        series_legend(&mut chart)?;
        root.present().map_err(err)?;
    }
    let img = RgbImage::from_raw(w, h, buf).ok_or_else(|| anyhow!("image buffer"))?;
    save(&img, path)
}

/// Coloured discs with the role names, left to right from `(x, y)`.
fn role_legend(img: &mut RgbImage, x: i32, y: i32, size: f64) -> Result<()> {
    let mut x = x;
    for role in ["leader", "follower", "predator"] {
        let c = role_colour(role);
        draw::disc(
            img,
            (x as f32 + 7.0, y as f32 + 0.6 * size as f32),
            7.0,
            Rgb([60, 60, 60]),
        );
        draw::disc(img, (x as f32 + 7.0, y as f32 + 0.6 * size as f32), 6.0, c);
        Label::new(role, size, BLACK).draw(img, x + 18, y)?;
        x += 18 + text_width(role, size) + 12;
    }
    Ok(())
}

/// Fig. 7: six moments of the featured run, chosen from its S(t) and alarm samples (the start, the
/// tightest aggregation, the alarm, the widest dispersion, the re-aggregation, the end), each screen
/// with its time and phase written under it, where no robot is.
pub fn fig7_snapshots(r: &Case2Result, path: &Path) -> Result<()> {
    let shown = featured_run(r);
    let run = &r.runs[shown];
    let moments = key_moments(run, 2.0 * r.config.sample_every.max(0.5));
    let times: Vec<f32> = moments.iter().map(|m| m.time).collect();
    let snaps = snapshots_at(&r.config, shown, &times)?;
    let Some(first) = snaps.first() else {
        return Err(anyhow!("run {shown} has no samples to show"));
    };
    let (w, h) = (first.width(), first.height());
    let (cols, gap, caption, title) = (3u32, 10u32, 28u32, 64u32);
    let rows = (snaps.len() as u32).div_ceil(cols);
    let mut img = RgbImage::from_pixel(
        cols * w + (cols + 1) * gap,
        title + rows * (h + caption + gap),
        Rgb([255, 255, 255]),
    );
    let heading = format!(
        "Case II, run {shown} (seed {}): AGP green around the leader, ALP red near the predator",
        r.config.scenario.spec.seed
    );
    Label::new(&heading, 20.0, BLACK).draw(&mut img, gap as i32, 6)?;
    role_legend(&mut img, gap as i32, 34, 17.0)?;
    for (k, (m, snap)) in moments.iter().zip(&snaps).enumerate() {
        let (c, rr) = (k as u32 % cols, k as u32 / cols);
        let (x, y) = (gap + c * (w + gap), title + rr * (h + caption + gap));
        image::imageops::replace(&mut img, snap, x as i64, y as i64);
        let phase = super::moments::phase_word(run, m.sample);
        let text = if m.what == phase {
            format!("({}) t = {:.1} s: {}", k + 1, m.time, phase)
        } else {
            format!("({}) t = {:.1} s: {} ({})", k + 1, m.time, m.what, phase)
        };
        let colour = if phase == "dispersion" {
            RGBColor(190, 30, 30)
        } else {
            RGBColor(20, 120, 40)
        };
        Label::new(&text, 17.0, colour).draw(&mut img, x as i32 + 2, (y + h + 4) as i32)?;
    }
    save(&img, path)
}

/// Case II trajectories of the featured run, every robot in its role's colour, over a dark arena.
pub fn case2_trajectories(r: &Case2Result, path: &Path) -> Result<()> {
    let shown = featured_run(r);
    let run = &r.runs[shown];
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
        draw::path(&mut img, &s, path_i, c);
        let shifted: Vec<_> = path_i
            .iter()
            .map(|p| *p + colcos_sim::prelude::Vec2::new(s.size[0] / w as f32, 0.0))
            .collect();
        draw::path(&mut img, &s, &shifted, c);
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
    let heading = format!(
        "Case II trajectories, run {shown}, {:.0} s (small dot: start, ring: end)",
        run.times.last().copied().unwrap_or(0.0)
    );
    Label::new(&heading, 20.0, WHITE).draw(&mut img, 10, 8)?;
    for (k, (name, c)) in legend.iter().enumerate() {
        let colour = RGBColor(c.0[0], c.0[1], c.0[2]);
        Label::new(name, 18.0, colour).draw(&mut img, 10, 36 + 22 * k as i32)?;
    }
    save(&img, path)
}
