//! An animated GIF of a run: the screen with the robots drawn on it, frame by frame.
use crate::error::{Result, SimError};
use crate::screen;
use crate::world::World;
use image::codecs::gif::{GifEncoder, Repeat};
use image::{Delay, Frame, Rgb};
use std::fs::File;
use std::io::BufWriter;
use std::path::Path;

pub struct GifRecorder {
    encoder: GifEncoder<BufWriter<File>>,
    path: String,
    width: u32,
    height: u32,
    delay_ms: u32,
}

impl GifRecorder {
    /// A GIF `width` pixels wide (height from the screen's aspect ratio) with one frame per
    /// `interval` seconds of simulated time, played back in real time.
    pub fn create(path: &Path, world: &World, width: u32, interval: f32) -> Result<Self> {
        let file = File::create(path)
            .map_err(|e| SimError::io(format!("creating {}", path.display()), e))?;
        let s = world.screen();
        let height = ((width as f32 * s.size[1] / s.size[0]).round() as u32).max(1);
        let mut encoder = GifEncoder::new_with_speed(BufWriter::new(file), 20);
        encoder
            .set_repeat(Repeat::Infinite)
            .map_err(|e| SimError::Image {
                path: path.display().to_string(),
                message: e.to_string(),
            })?;
        Ok(GifRecorder {
            encoder,
            path: path.display().to_string(),
            width,
            height,
            delay_ms: (interval * 1000.0).round().max(20.0) as u32,
        })
    }

    /// Adds the world as it is now.
    pub fn frame(&mut self, world: &World) -> Result<()> {
        let img = frame_image(world, self.width, self.height);
        let rgba = image::DynamicImage::ImageRgb8(img).into_rgba8();
        let frame = Frame::from_parts(rgba, 0, 0, Delay::from_numer_denom_ms(self.delay_ms, 1));
        self.encoder
            .encode_frame(frame)
            .map_err(|e| SimError::Image {
                path: self.path.clone(),
                message: e.to_string(),
            })
    }
}

/// The screen at `width x height` with every robot drawn on it in its group's colour, and a legend
/// naming the groups.
pub fn frame_image(world: &World, width: u32, height: u32) -> image::RgbImage {
    let mut img = screen::render(world.pheromones(), world.screen(), width, height);
    super::draw::robots(
        &mut img,
        world.screen(),
        world.poses(),
        world.robot_params().radius,
        &super::draw::robot_colours(world),
    );
    super::draw::legend(&mut img, &super::draw::group_legend(world));
    img
}

/// A stable light colour per role name, so groups can be told apart.
pub fn role_colour(role: &str) -> Rgb<u8> {
    let h = role
        .bytes()
        .fold(5381u32, |h, b| h.wrapping_mul(33) ^ b as u32);
    let palette = [
        [240, 240, 240],
        [255, 220, 90],
        [255, 160, 200],
        [170, 255, 170],
        [170, 210, 255],
        [255, 190, 120],
    ];
    Rgb(palette[(h as usize) % palette.len()])
}
