//! An animated GIF of a run: the screen with the robots drawn on it, frame by frame.
use crate::error::{Result, SimError};
use crate::screen;
use crate::world::World;
use image::codecs::gif::{GifEncoder, Repeat};
use image::{Delay, Frame, Rgb};
use std::fs::File;
use std::io::BufWriter;
use std::path::Path;

/// Most frames in a run's GIF.
pub const MAX_GIF_FRAMES: u64 = 1_000;
/// Most pixels in a run's GIF, all frames together: a GIF file takes about half a byte a pixel
/// (a 20-minute `three_trails` run, 858 frames of 480 x 270: 56 MB), so at most about 75 MB.
pub const MAX_GIF_PIXELS: u64 = 150_000_000;

/// Which ticks a run's GIF shows. One frame per `gif_interval`, unless that makes more than
/// [`MAX_GIF_FRAMES`] frames or more than [`MAX_GIF_PIXELS`] pixels in all: then a frame every
/// `thinned` intervals, `thinned` the smallest whole number that fits, each frame shown that much
/// longer so the GIF still plays in real time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GifPlan {
    /// Ticks between frames (a frame at tick 0 and at every multiple of it).
    pub every: u64,
    /// Simulated seconds between frames.
    pub interval: f32,
    /// How many `gif_interval`s one frame stands for (1: none thinned out).
    pub thinned: u64,
    /// Frames in a run of all its steps.
    pub frames: u64,
}

impl GifPlan {
    /// The plan for `steps` ticks of `dt` s with frames `width x height` px every `interval` s.
    pub fn new(steps: u64, dt: f32, interval: f32, width: u32, height: u32) -> GifPlan {
        let base = ((interval / dt).round() as u64).max(1);
        let pixels = (u64::from(width) * u64::from(height)).max(1);
        let cap = MAX_GIF_FRAMES.min(MAX_GIF_PIXELS / pixels).max(2);
        let wanted = (steps / base).saturating_add(1);
        let thinned = if wanted > cap {
            (wanted - 1).div_ceil(cap - 1)
        } else {
            1
        };
        let every = base.saturating_mul(thinned);
        GifPlan {
            every,
            // To the microsecond: `every x dt` in f32 would print as 2.6000001.
            interval: ((every as f64 * f64::from(dt) * 1e6).round() / 1e6) as f32,
            thinned,
            frames: (steps / every).saturating_add(1),
        }
    }
}

/// The height of a GIF frame `width` pixels wide, from the screen's aspect ratio.
pub fn frame_height(screen: &crate::screen::ScreenSpec, width: u32) -> u32 {
    ((width as f32 * screen.size[1] / screen.size[0]).round() as u32).max(1)
}

pub struct GifRecorder {
    encoder: GifEncoder<BufWriter<File>>,
    path: String,
    width: u32,
    height: u32,
    delay_ms: u32,
}

impl GifRecorder {
    /// A GIF `width` pixels wide (height from the screen's aspect ratio, [`frame_height`]) with one
    /// frame per `interval` seconds of simulated time, played back in real time.
    pub fn create(path: &Path, world: &World, width: u32, interval: f32) -> Result<Self> {
        Self::for_screen(path, world.screen(), width, interval)
    }

    /// [`GifRecorder::create`] for a screen of `screen`'s aspect ratio.
    pub fn for_screen(
        path: &Path,
        screen: &crate::screen::ScreenSpec,
        width: u32,
        interval: f32,
    ) -> Result<Self> {
        let file = File::create(path)
            .map_err(|e| SimError::io(format!("creating {}", path.display()), e))?;
        let height = frame_height(screen, width);
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
        self.image(frame_image(world, self.width, self.height))
    }

    /// The frame's size, pixels.
    pub fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// Adds `img` (of [`GifRecorder::size`]) as the next frame.
    pub fn image(&mut self, img: image::RgbImage) -> Result<()> {
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
    arena_image(world, &world.scenario().spec.robots, width, height)
}

/// [`frame_image`] of any arena (a rig's host: the robots at their tracked poses), its robots from
/// `groups`.
pub fn arena_image(
    view: &dyn crate::world::ArenaView,
    groups: &[crate::scenario::RobotGroupSpec],
    width: u32,
    height: u32,
) -> image::RgbImage {
    let mut img = screen::render(view.pheromones(), view.screen(), width, height);
    // Physical obstacles as the overhead camera sees them: outlines, under the robots.
    super::draw::obstacles(&mut img, view.screen(), view.obstacles());
    super::draw::robots(
        &mut img,
        view.screen(),
        view.poses(),
        view.robot_params().radius,
        &super::draw::robot_colours(view),
    );
    super::draw::legend(&mut img, &super::draw::groups_legend(groups));
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_short_run_keeps_every_interval() {
        let p = GifPlan::new(300, 0.02, 0.2, 480, 270);
        assert_eq!((p.every, p.thinned, p.frames), (10, 1, 31));
        assert!((p.interval - 0.2).abs() < 1e-6);
    }

    #[test]
    fn a_long_run_is_thinned_to_the_frame_limit_and_plays_in_real_time() {
        // Ten hours at 50 Hz, a frame every 0.2 s: 180,001 frames wanted.
        let steps = 10 * 3600 * 50;
        let p = GifPlan::new(steps, 0.02, 0.2, 480, 270);
        assert!(p.frames <= MAX_GIF_FRAMES, "{p:?}");
        assert!(
            p.frames > MAX_GIF_FRAMES / 2,
            "thinned no more than needed: {p:?}"
        );
        assert_eq!(p.every, 10 * p.thinned);
        assert!((p.interval - 0.2 * p.thinned as f32).abs() < 1e-3);
        // The smallest factor that fits: one less would not.
        assert!(steps / (10 * (p.thinned - 1)) + 1 > MAX_GIF_FRAMES);
    }

    #[test]
    fn large_frames_lower_the_frame_limit() {
        let p = GifPlan::new(30_000, 0.02, 0.02, 7_680, 4_320);
        assert!(p.frames * 7_680 * 4_320 <= MAX_GIF_PIXELS, "{p:?}");
        assert!(p.frames >= 2);
        // A frame every tick of a one-tick run stays as it is.
        assert_eq!(GifPlan::new(1, 0.02, 0.02, 7_680, 4_320).frames, 2);
    }
}
