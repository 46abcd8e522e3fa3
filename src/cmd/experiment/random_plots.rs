//! Figures of case I on random maps: the maps where a G3 trial missed the food, each with the paths of
//! those trials, and an overview of the first maps with every G3 trial.
use super::fig6::trajectories_panel;
use super::plots::{Label, save};
use super::random_run::{MapRun, RandomCase1, g3_failures};
use anyhow::Result;
use image::{Rgb, RgbImage};
use plotters::style::WHITE;
use std::path::Path;

/// Panels side by side, `columns` to a row, on white.
fn tile(panels: &[RgbImage], columns: usize) -> RgbImage {
    let (w, h) = (panels[0].width(), panels[0].height());
    let gap = 6;
    let cols = columns.min(panels.len()) as u32;
    let rows = panels.len().div_ceil(columns) as u32;
    let mut img = RgbImage::from_pixel(
        (w + gap) * cols - gap,
        (h + gap) * rows - gap,
        Rgb([255, 255, 255]),
    );
    for (k, p) in panels.iter().enumerate() {
        let (c, r) = ((k % columns) as u32, (k / columns) as u32);
        image::imageops::replace(&mut img, p, (c * (w + gap)) as i64, (r * (h + gap)) as i64);
    }
    img
}

/// The G3 panel of `m` with only the trials `keep`, titled `title`.
fn panel(m: &MapRun, keep: &[usize], title: &str, width: u32) -> Result<RgbImage> {
    let mut r = m.result.clone();
    let trials = std::mem::take(&mut r.groups[2].trials);
    r.groups[2].trials = keep.iter().map(|&k| trials[k].clone()).collect();
    let mut img = trajectories_panel(&r, 2, width)?;
    Label::new(title, 18.0, WHITE).boxed(&mut img, 6, 6)?;
    Ok(img)
}

/// `failures.png`: every map (at most `max`) where a G3 trial did not end at food, with the paths of
/// those trials (dot: where each ended). Returns false (and writes nothing) when there is none.
pub fn failures(r: &RandomCase1, path: &Path, max: usize) -> Result<bool> {
    let panels: Vec<RgbImage> = r
        .maps
        .iter()
        .filter_map(|m| {
            let f = g3_failures(m);
            (!f.is_empty()).then_some((m, f))
        })
        .take(max)
        .map(|(m, f)| {
            let title = format!(
                "{}: G3 missed the food in {} of {} trials (their paths), food {:?}",
                m.map.layout.name,
                f.len(),
                r.trials,
                m.map.foods
            );
            panel(m, &f, &title, 720)
        })
        .collect::<Result<_>>()?;
    if panels.is_empty() {
        return Ok(false);
    }
    save(&tile(&panels, 2), path)?;
    Ok(true)
}

/// `maps.png`: the first `max` maps with every G3 trial.
pub fn overview(r: &RandomCase1, path: &Path, max: usize) -> Result<()> {
    let panels: Vec<RgbImage> = r
        .maps
        .iter()
        .take(max)
        .map(|m| {
            let all: Vec<usize> = (0..m.result.groups[2].trials.len()).collect();
            let title = format!(
                "{} ({:?} corners, depth {}), food {:?}",
                m.map.layout.name, m.map.layout.corners, m.map.depth, m.map.foods
            );
            panel(m, &all, &title, 720)
        })
        .collect::<Result<_>>()?;
    if !panels.is_empty() {
        save(&tile(&panels, 3), path)?;
    }
    Ok(())
}
