//! What the figures share (a font compiled into the binary, so no system font is needed; labels on
//! images; saving) and Fig. 5, the bar charts of arrivals. Fig. 6 is in [`super::fig6`], Figs. 7 and
//! 8 in [`super::fig78`]. Drawn with plotters into memory and saved with the `image` crate.
use super::case1::Case1Result;
use anyhow::{Result, anyhow};
use colcos_sim::screen;
use image::RgbImage;
use plotters::prelude::*;
use plotters::style::FontStyle;
use std::path::Path;

use colcos_sim::output::draw::FONT;

/// Registers the compiled-in font as plotters' `sans-serif` (once; every chart's text needs it).
pub fn ensure_font() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, FONT);
    });
}

pub(super) fn err<E: std::fmt::Debug>(e: E) -> anyhow::Error {
    anyhow!("drawing: {e:?}")
}

pub(super) fn save(img: &RgbImage, path: &Path) -> Result<()> {
    screen::save_png(img, path)?;
    Ok(())
}

/// The series legend of the S(t) charts (Fig. 8 and the sim-to-real example's): top right, on a
/// nearly opaque white box, so every S(t) figure reads the same.
pub fn series_legend<'a, DB: DrawingBackend + 'a, CT: CoordTranslate>(
    chart: &mut ChartContext<'a, DB, CT>,
) -> Result<()> {
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .background_style(WHITE.mix(0.9))
        .border_style(BLACK)
        .label_font(("sans-serif", 16))
        .draw()
        .map_err(err)?;
    Ok(())
}

/// Text to write on an image: `size` pixels, in `colour`.
pub struct Label<'a> {
    pub text: &'a str,
    pub size: f64,
    pub colour: RGBColor,
}

impl<'a> Label<'a> {
    pub fn new(text: &'a str, size: f64, colour: RGBColor) -> Label<'a> {
        Label { text, size, colour }
    }

    /// Writes the text with its top-left at `(x, y)` pixels.
    pub fn draw(&self, img: &mut RgbImage, x: i32, y: i32) -> Result<()> {
        ensure_font();
        let (w, h) = img.dimensions();
        let buf: &mut [u8] = &mut *img;
        let root = BitMapBackend::with_buffer(buf, (w, h)).into_drawing_area();
        root.draw_text(
            self.text,
            &("sans-serif", self.size).into_font().color(&self.colour),
            (x, y),
        )
        .map_err(err)?;
        root.present().map_err(err)?;
        Ok(())
    }

    /// [`Label::draw`] with a dark box behind the text (readable over any screen colour).
    pub fn boxed(&self, img: &mut RgbImage, x: i32, y: i32) -> Result<()> {
        let wpx = text_width(self.text, self.size);
        let hpx = (self.size * 1.25) as i32;
        for yy in y.max(0)..(y + hpx).min(img.height() as i32) {
            for xx in x.max(0)..(x + wpx).min(img.width() as i32) {
                let p = img.get_pixel_mut(xx as u32, yy as u32);
                p.0 = p.0.map(|c| c / 4);
            }
        }
        self.draw(img, x + 3, y + 1)
    }
}

/// The width in pixels that a [`Label`] gives `text` at `size` (an upper bound for this font).
pub fn text_width(text: &str, size: f64) -> i32 {
    (text.chars().count() as f64 * size * 0.58) as i32 + 6
}

/// Fig. 5: arrivals per end point, one bar panel per group; the available food points are shaded and
/// their bars orange. Integer ticks, the count above each bar, no minor grid.
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
                "Case I: arrivals per end point, {} trials per group, layout {} (orange: available food {:?})",
                r.config.trials, r.config.layout.name, r.config.foods
            ),
            &("sans-serif", 22).into_font().color(&BLACK),
            (20, 14),
        )
        .map_err(err)?;
        let n = r.config.layout.ends.len();
        let most = r
            .groups
            .iter()
            .map(|g| g.counts.max_at_one_point())
            .max()
            .unwrap_or(1)
            .max(1) as i32;
        // Head room for the count above the tallest bar.
        let ymax = most + (most / 6).max(1);
        let panels = rest.split_evenly((r.groups.len(), 1));
        let food_shade = RGBColor(255, 236, 210);
        let food_bar = RGBColor(235, 130, 20);
        let bar = RGBColor(70, 110, 200);
        for (g, area) in r.groups.iter().zip(panels) {
            let caption = format!(
                "{} ({}): {} of {} at food, {} timeouts",
                g.name,
                g.pheromones.join(" + "),
                g.at_food(&r.config.foods),
                g.trials.len(),
                g.counts.timeouts
            );
            let mut chart = ChartBuilder::on(&area)
                .caption(caption, ("sans-serif", 20))
                .margin(10)
                .x_label_area_size(42)
                .y_label_area_size(50)
                .build_cartesian_2d(0.5f64..(n as f64 + 0.5), 0i32..ymax)
                .map_err(err)?;
            chart
                .draw_series(r.config.foods.iter().map(|&f| {
                    let x = f as f64;
                    Rectangle::new([(x - 0.48, 0), (x + 0.48, ymax)], food_shade.filled())
                }))
                .map_err(err)?;
            chart
                .configure_mesh()
                .disable_x_mesh()
                .light_line_style(TRANSPARENT)
                .bold_line_style(RGBColor(225, 225, 225))
                .x_labels(n)
                .x_label_formatter(&|x| format!("{}", x.round() as i64))
                .y_labels((ymax as usize + 1).min(6))
                .y_label_formatter(&|y| format!("{y}"))
                .x_desc("end point")
                .y_desc("arrivals")
                .label_style(("sans-serif", 16))
                .axis_desc_style(("sans-serif", 17))
                .draw()
                .map_err(err)?;
            let foods = &r.config.foods;
            chart
                .draw_series(g.counts.per_point.iter().enumerate().map(|(k, &c)| {
                    let x = (k + 1) as f64;
                    let colour = if foods.contains(&(k + 1)) {
                        food_bar
                    } else {
                        bar
                    };
                    Rectangle::new([(x - 0.35, 0), (x + 0.35, c as i32)], colour.filled())
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
                            let text = format!("{c}");
                            let dx = -text_width(&text, 16.0) / 2 + 3;
                            EmptyElement::at(((k + 1) as f64, c as i32))
                                + Text::new(text, (dx, -20), ("sans-serif", 16).into_font())
                        }),
                )
                .map_err(err)?;
        }
        root.present().map_err(err)?;
    }
    let img = RgbImage::from_raw(w, h, buf).ok_or_else(|| anyhow!("image buffer"))?;
    save(&img, path)
}
