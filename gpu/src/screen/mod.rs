//! The screen of eq. (1) composed on the GPU, and the colour sensors' footprint sampling on the GPU.
//!
//! A world's screen is a list of [`ScreenLayer`]s (one per pheromone, in the world's order): a grid
//! field of a [`GpuGrids`] batch, or a set of Gaussian sources. [`GpuScreen::render_to_buffer`]
//! composes the same 8-bit image as [`colcos_sim::screen::render`] ([`GpuScreen::read_image`]
//! reads it back); [`GpuScreen::sense`] gives the same mean levels as
//! [`colcos_sim::sensors::ColourSensor::screen_levels`] for many sensors of many worlds at once, and only
//! those readings come back.
//!
//! Gaussian sources are evaluated in f64 as on the CPU when the device has `SHADER_F64` (lavapipe and
//! NVIDIA do), with an f64 `exp` of our own (WGSL has none); without it, in f32, which can differ from
//! the CPU by one level where a pixel's sum lies within a few ulps of a rounding boundary.
mod batch;
mod sense;

pub use batch::{FootprintSets, SensorBatch};
pub use sense::mean_levels;

use crate::program::{ComputeProgram, READ, UNIFORM, WRITE, bind_buffers, shader_struct};
use crate::{GpuContext, GpuGrids, Result, storage};
use colcos_sim::field::{FieldModel, GaussianSource, Pheromone};
use colcos_sim::screen::ScreenSpec;
use colcos_sim::sensors::RING_POINTS;
use glam::Vec2;
use std::sync::Arc;

/// Points a sensor averages (its centre and the ring).
pub const POINTS_PER_SENSOR: usize = RING_POINTS + 1;

/// A Gaussian source as the screen needs it.
pub type GaussianLayerSource = GaussianSource;

/// One pheromone on the screen: colour `k_j` of eq. (1) and where its values come from.
#[derive(Clone, Debug)]
pub enum ScreenLayer {
    /// Field `field` of the [`GpuGrids`] batch.
    Grid { colour: [f32; 3], field: usize },
    /// Gaussian sources at clock `time`.
    Gaussian {
        colour: [f32; 3],
        sources: Vec<GaussianSource>,
        time: f32,
    },
}

/// The layers of every world of a batch (each world the same number of layers).
#[derive(Clone, Debug, Default)]
pub struct ScreenScene {
    pub worlds: Vec<Vec<ScreenLayer>>,
}

impl ScreenScene {
    /// The layers of one world's pheromones; `field_of(j)` gives the batch field of grid pheromone `j`.
    pub fn world_layers(
        pheromones: &[Pheromone],
        field_of: impl Fn(usize) -> Option<usize>,
    ) -> Vec<ScreenLayer> {
        pheromones
            .iter()
            .enumerate()
            .map(|(j, p)| match &p.model {
                FieldModel::Grid(_) => ScreenLayer::Grid {
                    colour: p.colour,
                    field: field_of(j).expect("a batch field for every grid pheromone"),
                },
                FieldModel::Gaussian(g) => ScreenLayer::Gaussian {
                    colour: p.colour,
                    sources: g.sources.clone(),
                    time: g.time,
                },
            })
            .collect()
    }
}

/// A colour sensor reading request: world `world`, footprint centred at `centre` (its sample points are
/// `centre + offsets`, see [`colcos_sim::sensors::ColourSensor::sample_points`]).
#[derive(Clone, Copy, Debug)]
pub struct SensorQuery {
    pub world: u32,
    pub points: [Vec2; POINTS_PER_SENSOR],
}

shader_struct! {
    /// One pheromone layer of a world as the shader reads it.
    struct LayerRec as Layer {
        /// 0 grid, 1 Gaussian.
        kind: u32,
        /// Grid: offset of the field's values in `vals`; Gaussian: its first source.
        offset: u32,
        /// Gaussian: number of sources.
        count: u32,
        _pad: u32,
        k: [f32; 3],
        /// Gaussian: the field's clock.
        time: f32,
    }
}

shader_struct! {
    /// One Gaussian source as the shader reads it.
    struct SrcRec as Src {
        k: f32,
        sx: f32,
        sy: f32,
        rho: f32,
        e: f32,
        cx: f32,
        cy: f32,
        start: f32,
        e_inf: u32,
        _p: [u32; 3],
    }
}

shader_struct! {
    /// The uniform of a render or sensing dispatch.
    struct Uni as U {
        width: u32,
        height: u32,
        nlayers: u32,
        nx: u32,
        ny: u32,
        groups_x: u32,
        /// Sensors.
        count: u32,
        /// Render: which world's layers.
        world: u32,
        cell: f32,
        /// Render: pixel size of the image, m.
        px: f32,
        py: f32,
        /// Sensors: pixel size of the panel, m.
        ps_x: f32,
        ps_y: f32,
        res_x: u32,
        res_y: u32,
        _pad: u32,
    }
}

// The shader's structs, byte for byte.
const _: () = assert!(std::mem::size_of::<LayerRec>() == 32);
const _: () = assert!(std::mem::size_of::<SrcRec>() == 48);
const _: () = assert!(std::mem::size_of::<Uni>() == 64);

/// exp in f64 arithmetic (WGSL's `exp` is f32/f16 only): Cody-Waite reduction, Taylor series to r^14;
/// within a few f64 ulps, so rounded to f32 it is the correctly rounded `expf` (as glibc's, nearly always).
pub(crate) const EXP64: &str = r#"
const LN2_HI: f64 = 6.93147180369123816490e-01;
const LN2_LO: f64 = 1.90821492927058770002e-10;
const INV_LN2: f64 = 1.44269504088896338700e+00;

fn exp64(x: f64) -> f64 {
    if (x < f64(-746.0)) { return f64(0.0); }
    let k = floor(x * INV_LN2 + f64(0.5));
    let r = (x - k * LN2_HI) - k * LN2_LO;
    var p = f64(1.0);
    for (var i = 14; i >= 1; i = i - 1) {
        p = f64(1.0) + r * p / f64(i);
    }
    return ldexp(p, i32(k));
}
"#;

const GAUSS_F64: &str = r#"
const PI64: f64 = 3.141592653589793;

fn exact64(x: f64) -> f64 {
    return select(x, f64(0.0), u._pad != 0u);
}

fn gauss(s: Src, x: f32, y: f32, t: f32) -> f32 {
    if (!(t >= s.start)) { return 0.0; }
    let tau = f64(t - s.start);
    let sx = f64(s.sx);
    let sy = f64(s.sy);
    let rho = f64(s.rho);
    let om = f64(1.0) - exact64(rho * rho);
    let dx = f64(x - s.cx);
    let dy = f64(y - s.cy);
    var decay = f64(1.0);
    if (s.e_inf == 0u) { decay = exp64(-tau / f64(s.e)); }
    let q = dx * dx / (sx * sx) + dy * dy / (sy * sy) - f64(2.0) * rho * dx * dy / (sx * sy);
    let norm = f64(s.k) / (f64(2.0) * PI64 * sx * sy * sqrt(om));
    return f32(norm * decay * exp64(-q / (f64(2.0) * om)));
}
"#;

const GAUSS_F32: &str = r#"
fn gauss(s: Src, x: f32, y: f32, t: f32) -> f32 {
    if (!(t >= s.start)) { return 0.0; }
    let tau = t - s.start;
    let om = 1.0 - s.rho * s.rho;
    let dx = x - s.cx;
    let dy = y - s.cy;
    var decay = 1.0;
    if (s.e_inf == 0u) { decay = exp(-tau / s.e); }
    let q = dx * dx / (s.sx * s.sx) + dy * dy / (s.sy * s.sy) - 2.0 * s.rho * dx * dy / (s.sx * s.sy);
    let norm = s.k / (2.0 * 3.14159265358979 * s.sx * s.sy * sqrt(om));
    return norm * decay * exp(-q / (2.0 * om));
}
"#;

/// Screen composition and sensor sampling pipelines.
pub struct GpuScreen {
    ctx: Arc<GpuContext>,
    layout: wgpu::BindGroupLayout,
    render: wgpu::ComputePipeline,
    sense: wgpu::ComputePipeline,
    sense_centres: wgpu::ComputePipeline,
    dummy: wgpu::Buffer,
    /// The last rendered image (packed RGBA8, one u32 per pixel), kept for display.
    image: Option<(wgpu::Buffer, u32, u32)>,
}

fn groups(items: usize, per: usize) -> (u32, u32) {
    let g = items.div_ceil(per).max(1) as u64;
    let gx = g.min(65535);
    (gx as u32, g.div_ceil(gx) as u32)
}

impl GpuScreen {
    /// Compiles the screen shader on `ctx`'s device.
    pub fn new(ctx: Arc<GpuContext>) -> Result<Self> {
        let c = ctx.clone();
        c.scoped("compiling the screen shader", || Self::build(ctx))
    }

    fn build(ctx: Arc<GpuContext>) -> Self {
        let structs = [LayerRec::WGSL, SrcRec::WGSL, Uni::WGSL].concat();
        let gauss = if ctx.f64 {
            format!("{EXP64}{GAUSS_F64}")
        } else {
            GAUSS_F32.to_string()
        };
        let src = include_str!("screen.wgsl")
            .replace("//STRUCTS//", &structs)
            .replace("//GAUSS//", &gauss);
        let device = &ctx.device;
        let program = ComputeProgram::new(
            device,
            "screen",
            src,
            &[READ, READ, READ, UNIFORM, WRITE, READ, READ, READ],
        );
        let pipe = |name: &str| program.pipeline(device, name);
        let render = pipe("render");
        let sense = pipe("sense");
        let sense_centres = pipe("sense_centres");
        let dummy = storage(&ctx, "colcos dummy", 16, wgpu::BufferUsages::empty());
        GpuScreen {
            layout: program.into_layout(),
            ctx,
            render,
            sense,
            sense_centres,
            dummy,
            image: None,
        }
    }

    pub fn context(&self) -> &Arc<GpuContext> {
        &self.ctx
    }

    /// Layer and source records of the scene; every world must have the same number of layers.
    fn records(
        grids: Option<&GpuGrids>,
        scene: &ScreenScene,
    ) -> Result<(Vec<LayerRec>, Vec<SrcRec>, u32)> {
        let nl = scene.worlds.first().map_or(0, |w| w.len());
        if scene.worlds.iter().any(|w| w.len() != nl) {
            return Err(crate::GpuError::Invalid(
                "every world of a scene needs the same number of layers".into(),
            ));
        }
        let mut layers = Vec::new();
        let mut srcs = Vec::new();
        for w in &scene.worlds {
            for l in w {
                layers.push(match l {
                    ScreenLayer::Grid { colour, field } => {
                        let g = grids.ok_or_else(|| {
                            crate::GpuError::Invalid("a grid layer needs a GpuGrids batch".into())
                        })?;
                        if *field >= g.len() {
                            return Err(crate::GpuError::Invalid(format!(
                                "layer field {field} of {}",
                                g.len()
                            )));
                        }
                        LayerRec {
                            kind: 0,
                            offset: g.field_offset(*field) as u32,
                            count: 0,
                            _pad: 0,
                            k: *colour,
                            time: 0.0,
                        }
                    }
                    ScreenLayer::Gaussian {
                        colour,
                        sources,
                        time,
                    } => {
                        let first = srcs.len() as u32;
                        srcs.extend(sources.iter().map(|s| SrcRec {
                            k: s.k,
                            sx: s.sigma_x,
                            sy: s.sigma_y,
                            rho: s.rho,
                            e: if s.evaporation.is_finite() {
                                s.evaporation
                            } else {
                                1.0
                            },
                            cx: s.centre.x,
                            cy: s.centre.y,
                            start: s.start,
                            e_inf: u32::from(s.evaporation.is_infinite()),
                            _p: [0; 3],
                        }));
                        LayerRec {
                            kind: 1,
                            offset: first,
                            count: sources.len() as u32,
                            _pad: 0,
                            k: *colour,
                            time: *time,
                        }
                    }
                });
            }
        }
        Ok((layers, srcs, nl as u32))
    }

    fn buffer_init(&self, label: &str, data: &[u8]) -> wgpu::Buffer {
        let b = storage(
            &self.ctx,
            label,
            data.len() as u64,
            wgpu::BufferUsages::empty(),
        );
        if !data.is_empty() {
            self.ctx.queue.write_buffer(&b, 0, data);
        }
        b
    }

    #[allow(clippy::too_many_arguments)]
    fn dispatch(
        &self,
        grids: Option<&GpuGrids>,
        scene: &ScreenScene,
        uni: Uni,
        pipe: &wgpu::ComputePipeline,
        out: &wgpu::Buffer,
        points: &[u8],
        qworld: &[u8],
        shape: (u32, u32),
    ) -> Result<()> {
        let (layers, srcs, nl) = Self::records(grids, scene)?;
        let uni = Uni { nlayers: nl, ..uni };
        self.ctx.scoped("composing the screen", || {
            self.dispatch_inner(
                grids,
                uni,
                pipe,
                out,
                (&layers, &srcs),
                points,
                qworld,
                shape,
            )
        })
    }

    #[allow(clippy::too_many_arguments)]
    fn dispatch_inner(
        &self,
        grids: Option<&GpuGrids>,
        uni: Uni,
        pipe: &wgpu::ComputePipeline,
        out: &wgpu::Buffer,
        (layers, srcs): (&[LayerRec], &[SrcRec]),
        points: &[u8],
        qworld: &[u8],
        shape: (u32, u32),
    ) {
        let lb = self.buffer_init("colcos layers", bytemuck::cast_slice(layers));
        let sb = self.buffer_init("colcos sources", bytemuck::cast_slice(srcs));
        let pb = self.buffer_init("colcos points", points);
        let qb = self.buffer_init("colcos sensor worlds", qworld);
        let ub = self.ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("colcos screen uniform"),
            size: std::mem::size_of::<Uni>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        self.ctx
            .queue
            .write_buffer(&ub, 0, bytemuck::bytes_of(&uni));
        let vals = grids.map_or(&self.dummy, |g| g.values_buffer());
        let bind = bind_buffers(
            &self.ctx.device,
            &self.layout,
            "colcos screen bind group",
            &[vals, &lb, &sb, &ub, out, &pb, &qb, &self.dummy],
        );
        let mut enc = self.ctx.device.create_command_encoder(&Default::default());
        {
            let mut pass = enc.begin_compute_pass(&Default::default());
            pass.set_pipeline(pipe);
            pass.set_bind_group(0, &bind, &[]);
            pass.dispatch_workgroups(shape.0, shape.1, 1);
        }
        self.ctx.queue.submit([enc.finish()]);
    }

    /// Composes world `world`'s screen at `width x height` into a GPU buffer of packed RGBA8 pixels
    /// (row 0 at the top), kept in [`GpuScreen::image_buffer`]; nothing is read back.
    pub fn render_to_buffer(
        &mut self,
        grids: Option<&GpuGrids>,
        scene: &ScreenScene,
        world: usize,
        screen: &ScreenSpec,
        width: u32,
        height: u32,
    ) -> Result<&wgpu::Buffer> {
        let pixels = width as u64 * height as u64;
        crate::check_size(&self.ctx, "screen image", pixels * 4)?;
        let reuse = matches!(&self.image, Some((_, w, h)) if *w == width && *h == height);
        if !reuse {
            let b = self.ctx.scoped("allocating the screen image", || {
                storage(
                    &self.ctx,
                    "colcos screen image",
                    pixels * 4,
                    wgpu::BufferUsages::empty(),
                )
            })?;
            self.image = Some((b, width, height));
        }
        let (gx, gy) = groups(pixels as usize, 256);
        let spec = grids.map(|g| *g.spec());
        let uni = Uni {
            width,
            height,
            nx: spec.map_or(1, |s| s.nx as u32),
            ny: spec.map_or(1, |s| s.ny as u32),
            groups_x: gx,
            world: world as u32,
            cell: spec.map_or(1.0, |s| s.cell),
            px: screen.size[0] / width.max(1) as f32,
            py: screen.size[1] / height.max(1) as f32,
            ..Default::default()
        };
        if pixels > 0 {
            let out = &self.image.as_ref().expect("set above").0;
            self.dispatch(grids, scene, uni, &self.render, out, &[], &[], (gx, gy))?;
        }
        Ok(&self.image.as_ref().expect("set above").0)
    }

    /// The last image of [`GpuScreen::render_to_buffer`]: (buffer, width, height).
    pub fn image_buffer(&self) -> Option<(&wgpu::Buffer, u32, u32)> {
        self.image.as_ref().map(|(b, w, h)| (b, *w, *h))
    }

    /// The last image of [`GpuScreen::render_to_buffer`] read back (the same pixels as
    /// [`colcos_sim::screen::render`]); an empty image before the first.
    pub fn read_image(&self) -> Result<image::RgbImage> {
        let Some((buf, width, height)) = self.image_buffer() else {
            return Ok(image::RgbImage::new(0, 0));
        };
        let mut img = image::RgbImage::new(width, height);
        let pixels = width as u64 * height as u64;
        if pixels == 0 {
            return Ok(img);
        }
        let bytes = self.ctx.read_buffer(buf, 0, pixels * 4)?;
        for (o, i) in img.chunks_exact_mut(3).zip(bytes.chunks_exact(4)) {
            o.copy_from_slice(&i[..3]);
        }
        Ok(img)
    }
}
