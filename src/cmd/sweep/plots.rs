//! The sweep's pictures, beside its table in `plots/`: each metric against each axis (the mean over
//! every run at that axis value, seeds and the other axes pooled, with its 95 % interval), and for every
//! pair of axes a heat map of each metric's mean. Sampled axes (more than 12 distinct values) are binned.
use super::data::{Groups, Table, by_group, by_pair, groups, short};
use anyhow::{Result, anyhow};
use colcos_sim::screen;
use image::RgbImage;
use plotters::prelude::*;
use plotters::style::FontStyle;
use std::path::{Path, PathBuf};

use colcos_sim::output::draw::FONT;

fn ensure_font() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, FONT);
    });
}

fn err<E: std::fmt::Debug>(e: E) -> anyhow::Error {
    anyhow!("drawing: {e:?}")
}

/// An axis of the table: its column, name and whether its values are on a log scale.
pub struct AxisInfo {
    pub name: String,
    pub log: bool,
}

/// A file name from a column name (`robots[1].count` -> `robots_1_.count`).
fn file_part(name: &str) -> String {
    colcos_sim::output::file_safe(name, &['.'])
}

/// Every picture of the sweep; returns the files written.
pub fn all(t: &Table, axes: &[AxisInfo], metrics: &[String], dir: &Path) -> Result<Vec<PathBuf>> {
    ensure_font();
    std::fs::create_dir_all(dir)?;
    let mut files = Vec::new();
    let grouped: Vec<Option<Groups>> = axes
        .iter()
        .map(|a| t.col(&a.name).map(|c| groups(t, c, a.log)))
        .collect();
    for m in metrics {
        let Some(mc) = t.col(m) else { continue };
        if t.rows.iter().all(|r| !r[mc].is_finite()) {
            continue;
        }
        for (a, g) in axes.iter().zip(&grouped) {
            let Some(g) = g else { continue };
            let path = dir.join(format!("{}_vs_{}.png", file_part(m), file_part(&a.name)));
            line(&path, m, a, g, &by_group(t, g, mc))?;
            files.push(path);
        }
        for i in 0..axes.len() {
            for j in i + 1..axes.len() {
                let (Some(gi), Some(gj)) = (&grouped[i], &grouped[j]) else {
                    continue;
                };
                let path = dir.join(format!(
                    "{}_{}_x_{}.png",
                    file_part(m),
                    file_part(&axes[i].name),
                    file_part(&axes[j].name)
                ));
                heat(
                    &path,
                    m,
                    (&axes[i], gi),
                    (&axes[j], gj),
                    &by_pair(t, gi, gj, mc),
                )?;
                files.push(path);
            }
        }
    }
    Ok(files)
}

const W: u32 = 720;
const H: u32 = 480;

fn save(buf: Vec<u8>, path: &Path) -> Result<()> {
    let img = RgbImage::from_raw(W, H, buf).ok_or_else(|| anyhow!("image buffer size"))?;
    screen::save_png(&img, path)?;
    Ok(())
}

/// The x ticks: one at each group (a swept value, a bin's centre, a category) with its label, so a log
/// axis reads 2.5, 5, 10 rather than the evenly spaced 2.5119, 3.9811 of its logarithm.
pub fn ticks(a: &AxisInfo, g: &Groups) -> Vec<(f64, String)> {
    xs(a, g).into_iter().zip(g.labels.iter().cloned()).collect()
}

/// A linear x axis whose ticks are given, not chosen by plotters (its own key-point wrapper loses
/// the formatting the mesh needs).
struct Ticked {
    inner: plotters::coord::types::RangedCoordf64,
    at: Vec<f64>,
}

impl Ranged for Ticked {
    type FormatOption = plotters::coord::ranged1d::DefaultFormatting;
    type ValueType = f64;

    fn map(&self, value: &f64, limit: (i32, i32)) -> i32 {
        self.inner.map(value, limit)
    }

    fn key_points<H: plotters::coord::ranged1d::KeyPointHint>(&self, hint: H) -> Vec<f64> {
        // The light mesh lines between ticks are not wanted; the ticks are all bold.
        if hint.weight().allow_light_points() || hint.max_num_points() == 0 {
            Vec::new()
        } else {
            self.at.clone()
        }
    }

    fn range(&self) -> std::ops::Range<f64> {
        self.inner.range()
    }
}

/// X positions: the values themselves, their log10 on a log axis, the index of a category.
fn xs(a: &AxisInfo, g: &Groups) -> Vec<f64> {
    let categorical = g
        .labels
        .iter()
        .zip(&g.centres)
        .any(|(l, c)| l.parse::<f64>().is_err() && *c == c.floor());
    let log = a.log && !categorical && g.centres.iter().all(|c| *c > 0.0);
    g.centres
        .iter()
        .map(|c| if log { c.log10() } else { *c })
        .collect()
}

fn padded(lo: f64, hi: f64) -> (f64, f64) {
    if !(lo.is_finite() && hi.is_finite()) {
        return (0.0, 1.0);
    }
    let pad = ((hi - lo) * 0.08).max(hi.abs().max(1e-9) * 0.05);
    (lo - pad, hi + pad)
}

fn line(
    path: &Path,
    metric: &str,
    a: &AxisInfo,
    g: &Groups,
    stats: &[Option<(f64, f64, usize)>],
) -> Result<()> {
    let x = xs(a, g);
    let ticks = ticks(a, g);
    let pts: Vec<(f64, f64, f64)> = x
        .iter()
        .zip(stats)
        .filter_map(|(x, s)| s.map(|(m, ci, _)| (*x, m, ci)))
        .collect();
    let mut buf = vec![255u8; (W * H * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buf, (W, H)).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        let (x0, x1) = padded(
            x.iter().copied().fold(f64::INFINITY, f64::min),
            x.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        );
        let (y0, y1) = padded(
            pts.iter().map(|p| p.1 - p.2).fold(f64::INFINITY, f64::min),
            pts.iter()
                .map(|p| p.1 + p.2)
                .fold(f64::NEG_INFINITY, f64::max),
        );
        let mut chart = ChartBuilder::on(&root)
            .caption(format!("{metric} against {}", a.name), ("sans-serif", 20))
            .margin(12)
            .x_label_area_size(45)
            .y_label_area_size(70)
            .build_cartesian_2d(
                Ticked {
                    inner: (x0..x1).into(),
                    at: ticks.iter().map(|t| t.0).collect(),
                },
                y0..y1,
            )
            .map_err(err)?;
        // Key points are the ticks' own positions: the label of the nearest one.
        let fmt = |v: &f64| {
            ticks
                .iter()
                .min_by(|p, q| (p.0 - v).abs().total_cmp(&(q.0 - v).abs()))
                .map(|t| t.1.clone())
                .unwrap_or_default()
        };
        let suffix = if g.discrete { "" } else { " (binned)" };
        chart
            .configure_mesh()
            .x_desc(format!("{}{suffix}", a.name))
            .y_desc(format!("{metric} (mean, 95 % interval)"))
            .x_label_formatter(&fmt)
            .y_label_formatter(&|v| short(*v))
            .draw()
            .map_err(err)?;
        let blue = RGBColor(31, 119, 180);
        chart
            .draw_series(LineSeries::new(
                pts.iter().map(|p| (p.0, p.1)),
                blue.stroke_width(2),
            ))
            .map_err(err)?;
        chart
            .draw_series(pts.iter().map(|p| {
                PathElement::new(
                    vec![(p.0, p.1 - p.2), (p.0, p.1 + p.2)],
                    blue.stroke_width(1),
                )
            }))
            .map_err(err)?;
        // Caps of the intervals, 1 % of the x range wide.
        let cap = (x1 - x0) * 0.01;
        chart
            .draw_series(pts.iter().flat_map(|p| {
                [p.1 - p.2, p.1 + p.2].map(|y| {
                    PathElement::new(vec![(p.0 - cap, y), (p.0 + cap, y)], blue.stroke_width(1))
                })
            }))
            .map_err(err)?;
        chart
            .draw_series(
                pts.iter()
                    .map(|p| Circle::new((p.0, p.1), 4, blue.filled())),
            )
            .map_err(err)?;
        root.present().map_err(err)?;
    }
    save(buf, path)
}

/// An axis title, saying when its values are binned.
fn binned(a: &AxisInfo, g: &Groups) -> String {
    if g.discrete {
        a.name.clone()
    } else {
        format!("{} (binned)", a.name)
    }
}

/// Viridis-like colour ramp at `f` in [0, 1].
fn ramp(f: f64) -> RGBColor {
    const STOPS: [(f64, [f64; 3]); 5] = [
        (0.0, [68.0, 1.0, 84.0]),
        (0.25, [59.0, 82.0, 139.0]),
        (0.5, [33.0, 145.0, 140.0]),
        (0.75, [94.0, 201.0, 98.0]),
        (1.0, [253.0, 231.0, 37.0]),
    ];
    let f = f.clamp(0.0, 1.0);
    let k = STOPS.iter().position(|s| s.0 >= f).unwrap_or(4).max(1);
    let (a, b) = (STOPS[k - 1], STOPS[k]);
    let u = (f - a.0) / (b.0 - a.0);
    let c = |i: usize| (a.1[i] + (b.1[i] - a.1[i]) * u).round() as u8;
    RGBColor(c(0), c(1), c(2))
}

fn heat(
    path: &Path,
    metric: &str,
    (a, ga): (&AxisInfo, &Groups),
    (b, gb): (&AxisInfo, &Groups),
    means: &[Vec<Option<f64>>],
) -> Result<()> {
    let all: Vec<f64> = means.iter().flatten().flatten().copied().collect();
    let lo = all.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = all.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let (na, nb) = (ga.centres.len(), gb.centres.len());
    let mut buf = vec![255u8; (W * H * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buf, (W, H)).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        let caption = format!(
            "{metric}: mean of each cell's runs ({} to {})",
            short(lo),
            short(hi)
        );
        let mut chart = ChartBuilder::on(&root)
            .caption(caption, ("sans-serif", 18))
            .margin(12)
            .x_label_area_size(45)
            .y_label_area_size(80)
            .build_cartesian_2d(0.0..na as f64, 0.0..nb as f64)
            .map_err(err)?;
        let label = |g: &Groups, v: f64| {
            let k = v.floor() as usize;
            if (v - k as f64 - 0.5).abs() < 1e-6 {
                g.labels.get(k).cloned().unwrap_or_default()
            } else {
                String::new()
            }
        };
        chart
            .configure_mesh()
            .disable_mesh()
            .x_desc(binned(a, ga))
            .y_desc(binned(b, gb))
            .x_labels(2 * na + 1)
            .y_labels(2 * nb + 1)
            .x_label_formatter(&|v| label(ga, *v))
            .y_label_formatter(&|v| label(gb, *v))
            .draw()
            .map_err(err)?;
        let span = (hi - lo).max(1e-300);
        let mut cells = Vec::new();
        let mut texts = Vec::new();
        for (i, row) in means.iter().enumerate() {
            for (j, m) in row.iter().enumerate() {
                let colour = match m {
                    Some(v) => ramp((v - lo) / span),
                    None => RGBColor(220, 220, 220),
                };
                let (x, y) = (i as f64, j as f64);
                cells.push(Rectangle::new(
                    [(x, y), (x + 1.0, y + 1.0)],
                    colour.filled(),
                ));
                if let (Some(v), true) = (m, na * nb <= 100) {
                    let dark = (v - lo) / span > 0.6;
                    let c = if dark { BLACK } else { WHITE };
                    texts.push(Text::new(
                        short(*v),
                        (x + 0.3, y + 0.55),
                        ("sans-serif", 13).into_font().color(&c),
                    ));
                }
            }
        }
        chart.draw_series(cells).map_err(err)?;
        chart.draw_series(texts).map_err(err)?;
        root.present().map_err(err)?;
    }
    save(buf, path)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_log_axis_is_ticked_at_its_swept_values() {
        let g = Groups {
            centres: vec![2.5, 5.0, 10.0, 20.0, 40.0],
            labels: ["2.5", "5", "10", "20", "40"].map(String::from).to_vec(),
            of_row: Vec::new(),
            discrete: true,
        };
        let a = AxisInfo {
            name: "e".into(),
            log: true,
        };
        let t = ticks(&a, &g);
        let labels: Vec<&str> = t.iter().map(|t| t.1.as_str()).collect();
        assert_eq!(labels, ["2.5", "5", "10", "20", "40"]);
        assert!((t[1].0 - 5f64.log10()).abs() < 1e-12, "{t:?}");
    }
}
