//! `colcos display SCENARIO`: the scenario's screen image, eq. (1), in a window at the field's rate (one
//! world step per frame), full screen on a chosen monitor or windowed; or `--png` headless.
#[cfg(feature = "display")]
use anyhow::Context;
use anyhow::Result;
use colcos_sim::field::BackendChoice;
use colcos_sim::prelude::*;
use colcos_sim::screen;
use std::path::PathBuf;

#[derive(clap::Args, Debug)]
pub struct DisplayArgs {
    /// Scenario file (TOML).
    pub scenario: PathBuf,
    /// Borderless full screen (on --monitor, default the primary one), image at the panel's resolution.
    #[arg(long)]
    pub fullscreen: bool,
    /// Monitor index (the window prints the list).
    #[arg(long)]
    pub monitor: Option<usize>,
    /// Image size WxH [default: the panel's resolution full screen, 960 pixels wide in a window].
    #[arg(long, value_parser = parse_size)]
    pub size: Option<(u32, u32)>,
    /// Present without waiting for vertical blank.
    #[arg(long)]
    pub no_vsync: bool,
    /// Headless: render the screen to this PNG (after --seconds of simulation) instead of a window.
    #[arg(long)]
    pub png: Option<PathBuf>,
    /// Simulated seconds before the headless PNG.
    #[arg(long, default_value_t = 0.0)]
    pub seconds: f32,
    /// Close the window after this many seconds of wall time.
    #[arg(long)]
    pub close_after: Option<f64>,
    /// Field backend: cpu, gpu or auto (overrides the scenario's `field.backend`).
    #[arg(long)]
    pub backend: Option<BackendChoice>,
}

fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s.split_once('x').ok_or("expected WxH, e.g. 1920x1080")?;
    let (w, h) = (
        w.parse::<u32>().map_err(|e| e.to_string())?,
        h.parse::<u32>().map_err(|e| e.to_string())?,
    );
    if w == 0 || h == 0 {
        return Err("the size must be positive".into());
    }
    // wgpu's default texture limit; beyond it a frame is gigabytes and its allocation aborts.
    if w > MAX_SIDE || h > MAX_SIDE {
        return Err(format!(
            "{w}x{h}: each side must be at most {MAX_SIDE} pixels"
        ));
    }
    Ok((w, h))
}

/// Widest and tallest image `--size` accepts, px.
const MAX_SIDE: u32 = 8192;

#[cfg(feature = "display")]
fn rgba(img: image::RgbImage) -> Vec<u8> {
    image::DynamicImage::ImageRgb8(img).to_rgba8().into_raw()
}

#[cfg(feature = "display")]
struct WorldFrames {
    world: World,
    size: (u32, u32),
    first: bool,
    /// The screen composed on the GPU that steps the fields (None: on the CPU).
    gpu: Option<GpuFrames>,
}

/// Eq. (1) on the field backend's GPU, into a buffer the window copies from on the same device.
#[cfg(feature = "display")]
struct GpuFrames {
    ctx: std::sync::Arc<colcos_gpu::GpuContext>,
    screen: colcos_gpu::GpuScreen,
    /// The world's grid fields (the backend's copies lack the step's trail deposits, which the world
    /// adds on the CPU after the field step: the current values are uploaded before each frame).
    grids: Option<colcos_gpu::GpuGrids>,
    /// Batch field of each pheromone (None: not a grid).
    map: Vec<Option<usize>>,
}

#[cfg(feature = "display")]
impl GpuFrames {
    fn new(ctx: std::sync::Arc<colcos_gpu::GpuContext>, world: &World) -> Result<Self> {
        use colcos_sim::field::{FieldModel, GridField};
        let mut map = Vec::new();
        let mut fields: Vec<&GridField> = Vec::new();
        for p in world.pheromones() {
            match &p.model {
                FieldModel::Grid(g) => {
                    map.push(Some(fields.len()));
                    fields.push(g);
                }
                FieldModel::Gaussian(_) => map.push(None),
            }
        }
        let grids = if fields.is_empty() {
            None
        } else {
            Some(colcos_gpu::GpuGrids::from_fields(ctx.clone(), &fields)?)
        };
        Ok(GpuFrames {
            screen: colcos_gpu::GpuScreen::new(ctx.clone())?,
            ctx,
            grids,
            map,
        })
    }

    /// Uploads the world's current grid values; the screen's layers.
    fn upload(&mut self, world: &World) -> Result<colcos_gpu::ScreenScene> {
        use colcos_sim::field::FieldModel;
        if let Some(grids) = self.grids.as_mut() {
            for (p, m) in world.pheromones().iter().zip(&self.map) {
                if let (FieldModel::Grid(g), Some(f)) = (&p.model, m) {
                    grids.write_field(*f, g.values())?;
                }
            }
        }
        Ok(colcos_gpu::ScreenScene {
            worlds: vec![colcos_gpu::ScreenScene::world_layers(
                world.pheromones(),
                |j| self.map[j],
            )],
        })
    }

    /// The screen, composed on the GPU into a buffer (packed RGBA8) that stays there.
    fn render(&mut self, world: &World, size: (u32, u32)) -> Result<colcos_gpu::wgpu::Buffer> {
        let scene = self.upload(world)?;
        Ok(self
            .screen
            .render_to_buffer(
                self.grids.as_ref(),
                &scene,
                0,
                world.screen(),
                size.0,
                size.1,
            )?
            .clone())
    }
}

#[cfg(feature = "display")]
impl colcos_display::FrameSource for WorldFrames {
    fn size(&self) -> (u32, u32) {
        self.size
    }
    fn next_frame(&mut self) -> Option<colcos_display::Frame> {
        if !self.first {
            if self.world.is_finished() {
                return None;
            }
            self.world.step();
        }
        self.first = false;
        // Printed obstacles are painted on the CPU: a world with some composes its screen there.
        if let Some(g) = self.gpu.as_mut()
            && self.world.obstacles().printed().is_none()
        {
            match g.render(&self.world, self.size) {
                Ok(b) => return Some(colcos_display::Frame::Buffer(b)),
                Err(e) => {
                    eprintln!("colcos display: the GPU screen failed ({e}); composing on the CPU");
                    self.gpu = None;
                }
            }
        }
        let s = *self.world.screen();
        let mut img = screen::render(self.world.pheromones(), &s, self.size.0, self.size.1);
        if let Some(printed) = self.world.obstacles().printed() {
            printed.paint(&mut img, &s);
        }
        Some(colcos_display::Frame::Rgba(rgba(img)))
    }
    fn device(&self) -> Option<colcos_display::SharedDevice> {
        self.gpu.as_ref().map(|g| colcos_display::SharedDevice {
            instance: g.ctx.instance.clone(),
            adapter: g.ctx.adapter.clone(),
            device: g.ctx.device.clone(),
            queue: g.ctx.queue.clone(),
        })
    }
}

pub fn main(args: DisplayArgs) -> Result<()> {
    let mut sc = Scenario::from_file(&args.scenario)?;
    if let Some(b) = args.backend {
        sc.spec.field.backend = b;
    }
    let mut world = World::new(&sc)?;
    #[cfg(feature = "display")]
    let (backend, gpu_ctx) = {
        let choice = sc.spec.field.backend;
        let shared = colcos_gpu::SharedBackend::resolve(choice)
            .map_err(|e| anyhow::anyhow!("field backend {choice}: {e}"))?;
        let sel = shared.install(&mut world)?;
        (sel.to_string(), shared.context().cloned())
    };
    #[cfg(not(feature = "display"))]
    let backend = crate::backend::install(&mut world, sc.spec.field.backend)?;
    eprintln!("field backend: {backend}");
    let res = sc.spec.screen.resolution;
    let size = args
        .size
        .unwrap_or(if args.fullscreen || args.png.is_some() {
            (res[0], res[1])
        } else {
            (
                960,
                ((960.0 * res[1] as f64 / res[0].max(1) as f64).round() as u32).max(1),
            )
        });
    if let Some(png) = &args.png {
        while world.time() + 0.5 * world.dt() < args.seconds && !world.is_finished() {
            world.step();
        }
        #[cfg(feature = "display")]
        let img = match &gpu_ctx {
            // The GPU that stepped the fields composes the screen too.
            Some(ctx) => {
                let mut g = GpuFrames::new(ctx.clone(), &world)?;
                let scene = g.upload(&world)?;
                let (grids, screen) = (g.grids.as_ref(), world.screen());
                g.screen
                    .render_to_buffer(grids, &scene, 0, screen, size.0, size.1)?;
                g.screen.read_image()?
            }
            None => screen::render(world.pheromones(), world.screen(), size.0, size.1),
        };
        #[cfg(not(feature = "display"))]
        let img = screen::render(world.pheromones(), world.screen(), size.0, size.1);
        let mut img = img;
        if let Some(printed) = world.obstacles().printed() {
            printed.paint(&mut img, world.screen());
        }
        #[cfg(feature = "display")]
        let img = {
            let rgba =
                image::RgbaImage::from_raw(size.0, size.1, rgba(img)).context("image buffer")?;
            colcos_display::render_headless(&rgba, size)?
        };
        screen::save_png(&img, png)?;
        return crate::report::print_report(&format!("wrote {}\n", png.display()));
    }
    #[cfg(feature = "display")]
    {
        let opts = colcos_display::DisplayOptions {
            title: format!("colcos: {}", sc.spec.name),
            fullscreen: args.fullscreen,
            monitor: args.monitor,
            window_size: None,
            position: None,
            decorations: true,
            vsync: !args.no_vsync,
            frame_period: std::time::Duration::from_secs_f32(sc.spec.dt),
            close_after: args.close_after.map(std::time::Duration::from_secs_f64),
            announce_first_frame: false,
        };
        let gpu = match gpu_ctx {
            Some(ctx) => Some(GpuFrames::new(ctx, &world)?),
            None => None,
        };
        eprintln!(
            "screen composed on the {}",
            if gpu.is_some() { "GPU" } else { "CPU" }
        );
        colcos_display::run_window(
            opts,
            Box::new(WorldFrames {
                world,
                size,
                first: true,
                gpu,
            }),
        )
        .context("display window")
    }
    #[cfg(not(feature = "display"))]
    {
        let _ = world;
        anyhow::bail!("this colcos was built without the `display` feature")
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn sizes_are_bounded_before_anything_is_allocated() {
        assert_eq!(super::parse_size("640x360"), Ok((640, 360)));
        assert_eq!(super::parse_size("8192x8192"), Ok((8192, 8192)));
        let e = super::parse_size("100000x100000").unwrap_err();
        assert!(e.contains("100000x100000") && e.contains("8192"), "{e}");
        assert!(super::parse_size("0x10").is_err());
        assert!(super::parse_size("10").is_err());
    }
}
