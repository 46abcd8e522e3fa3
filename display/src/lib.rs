//! colcos-display: the screen image of eq. (1) in a window (winit 0.30 + wgpu), full screen on a chosen
//! monitor or windowed, refreshed at the field's rate with vsync; and headless rendering of the same
//! image, through the same pipeline, to PNG.
//!
//! The image is shown pixel for pixel when the window has its size, otherwise scaled by the largest
//! factor that fits (nearest neighbour, aspect kept, black bars). Colours are written to a non-sRGB
//! target, so the 8-bit levels of eq. (1) reach the panel unchanged.
use std::sync::Arc;
use std::time::{Duration, Instant};
use winit::application::ApplicationHandler;
use winit::event::{ElementState, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::keyboard::{Key, NamedKey};
use winit::window::{Fullscreen, Window, WindowId};

#[derive(Debug, thiserror::Error)]
pub enum DisplayError {
    #[error(
        "no display to open a window on ({0}); set DISPLAY/WAYLAND_DISPLAY, or render headless to PNG"
    )]
    NoDisplay(String),
    #[error(
        "no GPU adapter for the window (wgpu: {0}); install a Vulkan driver (e.g. mesa-vulkan-drivers)"
    )]
    NoAdapter(String),
    #[error("monitor {index} does not exist ({count} found: {names})")]
    NoMonitor {
        index: usize,
        count: usize,
        names: String,
    },
    #[error("window: {0}")]
    Window(String),
    #[error("GPU: {0}")]
    Gpu(String),
}

pub type Result<T> = std::result::Result<T, DisplayError>;

/// The wgpu this crate is built on (for [`SharedDevice`] and [`Frame::Buffer`]).
pub use wgpu;

mod viewer;
pub use viewer::Viewer;

/// One image to show.
#[derive(Clone, Debug)]
pub enum Frame {
    /// RGBA8 bytes, row 0 at the top.
    Rgba(Vec<u8>),
    /// A buffer on the source's device ([`FrameSource::device`]) holding the image as packed RGBA8
    /// (`width * height * 4` bytes, row 0 at the top, e.g. `colcos_gpu::GpuScreen::render_to_buffer`).
    /// When the window shares that device the image goes from the buffer to the window's texture on
    /// the GPU; otherwise it is read back and uploaded.
    Buffer(wgpu::Buffer),
}

/// A device opened elsewhere (e.g. the GPU field backend's) that a window can present with: the
/// surface is made from `instance`, and used when `adapter` supports it.
#[derive(Clone, Debug)]
pub struct SharedDevice {
    pub instance: wgpu::Instance,
    pub adapter: wgpu::Adapter,
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
}

/// Supplies the images to show.
pub trait FrameSource {
    /// Image size, pixels.
    fn size(&self) -> (u32, u32);
    /// The next image, called once per frame period; `None` keeps the last one on screen (a finished
    /// or paused run).
    fn next_frame(&mut self) -> Option<Frame>;
    /// The device the source renders on, for [`Frame::Buffer`]s; `None`: the window opens its own.
    fn device(&self) -> Option<SharedDevice> {
        None
    }
}

/// A fixed image.
pub struct StillImage(pub image::RgbaImage, bool);

impl StillImage {
    pub fn new(img: image::RgbaImage) -> Self {
        StillImage(img, false)
    }
}

impl FrameSource for StillImage {
    fn size(&self) -> (u32, u32) {
        self.0.dimensions()
    }
    fn next_frame(&mut self) -> Option<Frame> {
        if self.1 {
            return None;
        }
        self.1 = true;
        Some(Frame::Rgba(self.0.as_raw().clone()))
    }
}

/// How the window shows the image.
#[derive(Clone, Debug)]
pub struct DisplayOptions {
    pub title: String,
    /// Borderless full screen on `monitor` (default: the primary one).
    pub fullscreen: bool,
    /// Index into the monitors winit lists (printed when the window opens).
    pub monitor: Option<usize>,
    /// Inner size of the window when not full screen (default: the image size).
    pub window_size: Option<(u32, u32)>,
    /// Window position when not full screen.
    pub position: Option<(i32, i32)>,
    /// Window decorations (title bar) when not full screen.
    pub decorations: bool,
    /// Wait for the monitor's vertical blank (Fifo presentation); without it, present at once.
    pub vsync: bool,
    /// Time between frames (the field's rate: the scenario's dt).
    pub frame_period: Duration,
    /// Close after this long (None: when the user closes the window or presses Esc/q).
    pub close_after: Option<Duration>,
    /// Print one line on stdout when the first frame has been presented (tests wait for it).
    pub announce_first_frame: bool,
}

impl Default for DisplayOptions {
    fn default() -> Self {
        DisplayOptions {
            title: "colcos".into(),
            fullscreen: false,
            monitor: None,
            window_size: None,
            position: None,
            decorations: true,
            vsync: true,
            frame_period: Duration::from_millis(20),
            close_after: None,
            announce_first_frame: false,
        }
    }
}

const SHADER: &str = r#"
struct V {
    img: vec2<f32>,
    off: vec2<f32>,
    scale: vec2<f32>,
    _pad: vec2<f32>,
};
@group(0) @binding(0) var tex: texture_2d<f32>;
@group(0) @binding(1) var<uniform> v: V;

@vertex
fn vs(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    let x = f32((i << 1u) & 2u);
    let y = f32(i & 2u);
    return vec4<f32>(x * 2.0 - 1.0, 1.0 - y * 2.0, 0.0, 1.0);
}

@fragment
fn fs(@builtin(position) p: vec4<f32>) -> @location(0) vec4<f32> {
    let q = (p.xy - v.off) * v.scale;
    if (q.x < 0.0 || q.y < 0.0 || q.x >= v.img.x || q.y >= v.img.y) {
        return vec4<f32>(0.0, 0.0, 0.0, 1.0);
    }
    let c = textureLoad(tex, vec2<i32>(floor(q)), 0);
    return vec4<f32>(c.rgb, 1.0);
}
"#;

/// The image texture and the pipeline that draws it onto a target of some format and size.
pub struct Presenter {
    device: wgpu::Device,
    queue: wgpu::Queue,
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
    texture: wgpu::Texture,
    uniform: wgpu::Buffer,
    bind: wgpu::BindGroup,
    size: (u32, u32),
}

impl Presenter {
    pub fn new(
        device: wgpu::Device,
        queue: wgpu::Queue,
        target: wgpu::TextureFormat,
        size: (u32, u32),
    ) -> Self {
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("colcos display"),
            source: wgpu::ShaderSource::Wgsl(SHADER.into()),
        });
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: None,
            entries: &[
                wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Float { filterable: false },
                        view_dimension: wgpu::TextureViewDimension::D2,
                        multisampled: false,
                    },
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 1,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Uniform,
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                    count: None,
                },
            ],
        });
        let pl = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: None,
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("colcos display"),
            layout: Some(&pl),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: wgpu::PrimitiveState::default(),
            depth_stencil: None,
            multisample: wgpu::MultisampleState::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs"),
                compilation_options: Default::default(),
                targets: &[Some(wgpu::ColorTargetState {
                    format: target,
                    blend: None,
                    write_mask: wgpu::ColorWrites::ALL,
                })],
            }),
            multiview_mask: None,
            cache: None,
        });
        let uniform = device.create_buffer(&wgpu::BufferDescriptor {
            label: None,
            size: 32,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let (texture, bind) = Self::make_texture(&device, &layout, &uniform, size);
        Presenter {
            device,
            queue,
            pipeline,
            layout,
            texture,
            uniform,
            bind,
            size,
        }
    }

    fn make_texture(
        device: &wgpu::Device,
        layout: &wgpu::BindGroupLayout,
        uniform: &wgpu::Buffer,
        size: (u32, u32),
    ) -> (wgpu::Texture, wgpu::BindGroup) {
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("colcos screen image"),
            size: wgpu::Extent3d {
                width: size.0.max(1),
                height: size.1.max(1),
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rgba8Unorm,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        });
        let view = texture.create_view(&Default::default());
        let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: None,
            layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::TextureView(&view),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: uniform.as_entire_binding(),
                },
            ],
        });
        (texture, bind)
    }

    /// Replaces the texture when `size` changes; false for an empty image (nothing to copy).
    fn fit_texture(&mut self, size: (u32, u32)) -> bool {
        if size != self.size {
            let (t, b) = Self::make_texture(&self.device, &self.layout, &self.uniform, size);
            self.texture = t;
            self.bind = b;
            self.size = size;
        }
        size.0 != 0 && size.1 != 0
    }

    /// Uploads an RGBA8 image of `size` (replacing the texture when the size changes).
    pub fn upload(&mut self, rgba: &[u8], size: (u32, u32)) {
        if !self.fit_texture(size) {
            return;
        }
        self.queue.write_texture(
            wgpu::TexelCopyTextureInfo {
                texture: &self.texture,
                mip_level: 0,
                origin: wgpu::Origin3d::ZERO,
                aspect: wgpu::TextureAspect::All,
            },
            rgba,
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(4 * size.0),
                rows_per_image: Some(size.1),
            },
            wgpu::Extent3d {
                width: size.0,
                height: size.1,
                depth_or_array_layers: 1,
            },
        );
    }

    /// Copies an image of `size` from `buffer` (packed RGBA8, on this presenter's device) into the
    /// texture, on the GPU.
    pub fn upload_buffer(&mut self, buffer: &wgpu::Buffer, size: (u32, u32)) {
        if !self.fit_texture(size) {
            return;
        }
        let row = 4 * size.0;
        let mut enc = self.device.create_command_encoder(&Default::default());
        let copy = |enc: &mut wgpu::CommandEncoder, y: u32, rows: u32| {
            enc.copy_buffer_to_texture(
                wgpu::TexelCopyBufferInfo {
                    buffer,
                    layout: wgpu::TexelCopyBufferLayout {
                        offset: y as u64 * row as u64,
                        bytes_per_row: (rows > 1).then_some(row),
                        rows_per_image: None,
                    },
                },
                wgpu::TexelCopyTextureInfo {
                    texture: &self.texture,
                    mip_level: 0,
                    origin: wgpu::Origin3d { x: 0, y, z: 0 },
                    aspect: wgpu::TextureAspect::All,
                },
                wgpu::Extent3d {
                    width: size.0,
                    height: rows,
                    depth_or_array_layers: 1,
                },
            );
        };
        if row.is_multiple_of(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT) {
            copy(&mut enc, 0, size.1);
        } else {
            // Rows not 256-byte aligned: one copy per row (a single row needs no alignment).
            for y in 0..size.1 {
                copy(&mut enc, y, 1);
            }
        }
        self.queue.submit([enc.finish()]);
    }

    /// Draws the image onto `target` (`target_size` pixels): 1:1 when the sizes agree, else scaled to fit.
    pub fn draw(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        target: &wgpu::TextureView,
        target_size: (u32, u32),
    ) {
        let (w, h) = (self.size.0.max(1) as f32, self.size.1.max(1) as f32);
        let (tw, th) = (target_size.0 as f32, target_size.1 as f32);
        let s = (tw / w).min(th / h);
        let s = if (s - 1.0).abs() < 1e-6 { 1.0 } else { s };
        let off = [((tw - w * s) * 0.5).floor(), ((th - h * s) * 0.5).floor()];
        let data: [f32; 8] = [w, h, off[0], off[1], 1.0 / s, 1.0 / s, 0.0, 0.0];
        self.queue
            .write_buffer(&self.uniform, 0, bytemuck_cast(&data));
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("colcos display"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: target,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: None,
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &self.bind, &[]);
        pass.draw(0..3, 0..1);
    }
}

fn bytemuck_cast(data: &[f32; 8]) -> &[u8] {
    // SAFETY: f32 has no padding or invalid bit patterns; the slice covers exactly the array.
    unsafe { std::slice::from_raw_parts(data.as_ptr().cast::<u8>(), std::mem::size_of_val(data)) }
}

fn instance() -> wgpu::Instance {
    wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env())
}

/// Renders `img` (RGBA8) through the display pipeline into an offscreen target of `size` and reads it
/// back: exactly what the window shows at that size.
pub fn render_headless(img: &image::RgbaImage, size: (u32, u32)) -> Result<image::RgbImage> {
    let inst = instance();
    let adapter = pollster::block_on(inst.request_adapter(&wgpu::RequestAdapterOptions::default()))
        .map_err(|e| DisplayError::NoAdapter(e.to_string()))?;
    let (device, queue) =
        pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor::default()))
            .map_err(|e| DisplayError::Gpu(e.to_string()))?;
    let dev = SharedDevice {
        instance: inst,
        adapter,
        device,
        queue,
    };
    render_headless_frame(
        &dev,
        Frame::Rgba(img.as_raw().clone()),
        img.dimensions(),
        size,
    )
}

/// [`render_headless`] of a [`Frame`] of `img_size` on a given device (a [`Frame::Buffer`] must be
/// on it): the window's pipeline, drawn into an offscreen target of `size` and read back.
pub fn render_headless_frame(
    dev: &SharedDevice,
    frame: Frame,
    img_size: (u32, u32),
    size: (u32, u32),
) -> Result<image::RgbImage> {
    let (device, queue) = (&dev.device, &dev.queue);
    let format = wgpu::TextureFormat::Rgba8Unorm;
    let mut p = Presenter::new(device.clone(), queue.clone(), format, img_size);
    match frame {
        Frame::Rgba(rgba) => p.upload(&rgba, img_size),
        Frame::Buffer(b) => p.upload_buffer(&b, img_size),
    }
    let target = device.create_texture(&wgpu::TextureDescriptor {
        label: Some("colcos headless target"),
        size: wgpu::Extent3d {
            width: size.0,
            height: size.1,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
        view_formats: &[],
    });
    let row = (4 * size.0).next_multiple_of(256);
    let buf = device.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size: row as u64 * size.1 as u64,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut enc = device.create_command_encoder(&Default::default());
    p.draw(&mut enc, &target.create_view(&Default::default()), size);
    enc.copy_texture_to_buffer(
        wgpu::TexelCopyTextureInfo {
            texture: &target,
            mip_level: 0,
            origin: wgpu::Origin3d::ZERO,
            aspect: wgpu::TextureAspect::All,
        },
        wgpu::TexelCopyBufferInfo {
            buffer: &buf,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(row),
                rows_per_image: Some(size.1),
            },
        },
        wgpu::Extent3d {
            width: size.0,
            height: size.1,
            depth_or_array_layers: 1,
        },
    );
    queue.submit([enc.finish()]);
    let (tx, rx) = std::sync::mpsc::channel();
    buf.map_async(wgpu::MapMode::Read, .., move |r| {
        let _ = tx.send(r);
    });
    device
        .poll(wgpu::PollType::wait_indefinitely())
        .map_err(|e| DisplayError::Gpu(e.to_string()))?;
    rx.recv()
        .map_err(|e| DisplayError::Gpu(e.to_string()))?
        .map_err(|e| DisplayError::Gpu(e.to_string()))?;
    let mut out = image::RgbImage::new(size.0, size.1);
    {
        let view = buf
            .get_mapped_range(..)
            .map_err(|e| DisplayError::Gpu(format!("{e:?}")))?;
        for y in 0..size.1 as usize {
            let src = &view[y * row as usize..][..4 * size.0 as usize];
            let dst = &mut out.as_mut()[y * 3 * size.0 as usize..][..3 * size.0 as usize];
            for (d, s) in dst.chunks_exact_mut(3).zip(src.chunks_exact(4)) {
                d.copy_from_slice(&s[..3]);
            }
        }
    }
    buf.unmap();
    Ok(out)
}

pub(crate) struct WindowState {
    pub(crate) window: Arc<Window>,
    surface: wgpu::Surface<'static>,
    config: wgpu::SurfaceConfiguration,
    presenter: Presenter,
    /// Whether the window presents with the source's device (its buffers need no read-back).
    shared: bool,
}

/// Opens a window for `opts` showing images of `size`, and a device to present with: `shared`'s when
/// its adapter supports the window's surface, otherwise one of the window's own.
pub(crate) fn open_window(
    el: &ActiveEventLoop,
    opts: &DisplayOptions,
    size: (u32, u32),
    shared: Option<&SharedDevice>,
) -> Result<WindowState> {
    let monitors: Vec<_> = el.available_monitors().collect();
    let names = monitors
        .iter()
        .enumerate()
        .map(|(i, m)| format!("{i}: {} {:?}", m.name().unwrap_or_default(), m.size()))
        .collect::<Vec<_>>()
        .join(", ");
    let monitor = match opts.monitor {
        Some(i) => Some(monitors.get(i).cloned().ok_or(DisplayError::NoMonitor {
            index: i,
            count: monitors.len(),
            names: names.clone(),
        })?),
        None => el.primary_monitor().or_else(|| monitors.first().cloned()),
    };
    eprintln!("colcos-display: monitors [{names}]");
    let wsize = opts.window_size.unwrap_or(size);
    let mut attrs = Window::default_attributes().with_title(opts.title.clone());
    if opts.fullscreen {
        // The monitor's size and position too: without a window manager (a bare X server, a kiosk)
        // the fullscreen hint alone does not resize the window.
        if let Some(m) = &monitor {
            attrs = attrs
                .with_inner_size(m.size())
                .with_position(m.position())
                .with_decorations(false);
        }
        attrs = attrs.with_fullscreen(Some(Fullscreen::Borderless(monitor)));
    } else {
        attrs = attrs
            .with_inner_size(winit::dpi::PhysicalSize::new(
                wsize.0.max(1),
                wsize.1.max(1),
            ))
            .with_decorations(opts.decorations)
            .with_resizable(true);
        if let Some((x, y)) = opts.position {
            attrs = attrs.with_position(winit::dpi::PhysicalPosition::new(x, y));
        }
    }
    let window = Arc::new(
        el.create_window(attrs)
            .map_err(|e| DisplayError::Window(e.to_string()))?,
    );
    let on_shared = shared.and_then(|s| {
        let surface = s.instance.create_surface(window.clone()).ok()?;
        s.adapter.is_surface_supported(&surface).then(|| {
            (
                surface,
                s.adapter.clone(),
                s.device.clone(),
                s.queue.clone(),
            )
        })
    });
    if shared.is_some() && on_shared.is_none() {
        eprintln!(
            "colcos-display: the source's GPU cannot present to this window; its images are read back through the CPU"
        );
    }
    let is_shared = on_shared.is_some();
    let (surface, adapter, device, queue) = match on_shared {
        Some(x) => x,
        None => {
            let inst = instance();
            let surface = inst
                .create_surface(window.clone())
                .map_err(|e| DisplayError::Gpu(e.to_string()))?;
            let adapter = pollster::block_on(inst.request_adapter(&wgpu::RequestAdapterOptions {
                compatible_surface: Some(&surface),
                ..Default::default()
            }))
            .map_err(|e| DisplayError::NoAdapter(e.to_string()))?;
            let (device, queue) =
                pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor::default()))
                    .map_err(|e| DisplayError::Gpu(e.to_string()))?;
            (surface, adapter, device, queue)
        }
    };
    eprintln!(
        "colcos-display: adapter {} ({:?}, {:?}){}",
        adapter.get_info().name,
        adapter.get_info().device_type,
        adapter.get_info().backend,
        if is_shared {
            ", the device of the field backend"
        } else {
            ""
        }
    );
    let inner = window.inner_size();
    let mut config = surface
        .get_default_config(&adapter, inner.width.max(1), inner.height.max(1))
        .ok_or_else(|| DisplayError::Gpu("the surface is not supported by the adapter".into()))?;
    let caps = surface.get_capabilities(&adapter);
    // A non-sRGB format, so the 8-bit levels are shown as they are.
    if let Some(f) = caps.formats.iter().find(|f| !f.is_srgb()) {
        config.format = *f;
    } else {
        config.view_formats = vec![config.format.remove_srgb_suffix()];
    }
    config.present_mode = if opts.vsync {
        wgpu::PresentMode::Fifo
    } else if caps.present_modes.contains(&wgpu::PresentMode::Immediate) {
        wgpu::PresentMode::Immediate
    } else {
        wgpu::PresentMode::AutoNoVsync
    };
    surface.configure(&device, &config);
    let view_format = config.format.remove_srgb_suffix();
    let presenter = Presenter::new(device, queue, view_format, size);
    Ok(WindowState {
        window,
        surface,
        config,
        presenter,
        shared: is_shared,
    })
}

/// Copies `buffer` (on `dev`) into CPU memory: `bytes` bytes (blocking).
fn read_back(dev: &SharedDevice, buffer: &wgpu::Buffer, bytes: u64) -> Result<Vec<u8>> {
    let staging = dev.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("colcos display read-back"),
        size: bytes.max(4).next_multiple_of(4),
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut enc = dev.device.create_command_encoder(&Default::default());
    enc.copy_buffer_to_buffer(buffer, 0, &staging, 0, bytes.next_multiple_of(4));
    dev.queue.submit([enc.finish()]);
    let (tx, rx) = std::sync::mpsc::channel();
    staging.map_async(wgpu::MapMode::Read, .., move |r| {
        let _ = tx.send(r);
    });
    dev.device
        .poll(wgpu::PollType::wait_indefinitely())
        .map_err(|e| DisplayError::Gpu(e.to_string()))?;
    rx.recv()
        .map_err(|e| DisplayError::Gpu(e.to_string()))?
        .map_err(|e| DisplayError::Gpu(e.to_string()))?;
    let out = staging
        .get_mapped_range(..)
        .map_err(|e| DisplayError::Gpu(format!("{e:?}")))?[..bytes as usize]
        .to_vec();
    staging.unmap();
    Ok(out)
}

impl WindowState {
    /// Puts `frame` (of `size`) into the window's texture; `source` is the device of buffer frames.
    pub(crate) fn set_frame(
        &mut self,
        frame: Frame,
        size: (u32, u32),
        source: Option<&SharedDevice>,
    ) -> Result<()> {
        match frame {
            Frame::Rgba(rgba) => self.presenter.upload(&rgba, size),
            Frame::Buffer(b) if self.shared => self.presenter.upload_buffer(&b, size),
            Frame::Buffer(b) => {
                let dev = source.ok_or_else(|| {
                    DisplayError::Gpu("a buffer frame from a source without a device".into())
                })?;
                let rgba = read_back(dev, &b, size.0 as u64 * size.1 as u64 * 4)?;
                self.presenter.upload(&rgba, size);
            }
        }
        Ok(())
    }

    /// Draws the texture and presents it; false when the surface had no frame to give.
    pub(crate) fn present(&mut self) -> bool {
        let frame = match self.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(t)
            | wgpu::CurrentSurfaceTexture::Suboptimal(t) => t,
            wgpu::CurrentSurfaceTexture::Timeout | wgpu::CurrentSurfaceTexture::Occluded => {
                return false;
            }
            _ => {
                self.surface.configure(&self.presenter.device, &self.config);
                return false;
            }
        };
        let view = frame.texture.create_view(&wgpu::TextureViewDescriptor {
            format: Some(self.config.format.remove_srgb_suffix()),
            ..Default::default()
        });
        let mut enc = self
            .presenter
            .device
            .create_command_encoder(&Default::default());
        self.presenter
            .draw(&mut enc, &view, (self.config.width, self.config.height));
        self.presenter.queue.submit([enc.finish()]);
        self.window.pre_present_notify();
        self.presenter.queue.present(frame);
        true
    }

    pub(crate) fn resize(&mut self, size: winit::dpi::PhysicalSize<u32>) {
        self.config.width = size.width.max(1);
        self.config.height = size.height.max(1);
        self.surface.configure(&self.presenter.device, &self.config);
        self.window.request_redraw();
    }
}

struct App {
    opts: DisplayOptions,
    source: Box<dyn FrameSource>,
    device: Option<SharedDevice>,
    state: Option<WindowState>,
    error: Option<DisplayError>,
    started: Instant,
    next_frame: Instant,
    presented: u64,
    /// The latest image, kept until the window exists.
    pending: Option<Frame>,
}

impl App {
    fn redraw(&mut self) -> Result<()> {
        let now = Instant::now();
        if now >= self.next_frame {
            if let Some(f) = self.source.next_frame() {
                self.pending = Some(f);
            }
            self.next_frame += self.opts.frame_period;
            if self.next_frame < now {
                self.next_frame = now + self.opts.frame_period;
            }
        }
        let size = self.source.size();
        let Some(st) = self.state.as_mut() else {
            return Ok(());
        };
        if let Some(f) = self.pending.take() {
            st.set_frame(f, size, self.device.as_ref())?;
        }
        if !st.present() {
            return Ok(());
        }
        self.presented += 1;
        if self.presented == 1 && self.opts.announce_first_frame {
            use std::io::Write;
            println!("colcos-display: first frame presented");
            let _ = std::io::stdout().flush();
        }
        Ok(())
    }
}

impl ApplicationHandler for App {
    fn resumed(&mut self, el: &ActiveEventLoop) {
        if self.state.is_some() {
            return;
        }
        match open_window(el, &self.opts, self.source.size(), self.device.as_ref()) {
            Ok(s) => {
                s.window.request_redraw();
                self.state = Some(s);
            }
            Err(e) => {
                self.error = Some(e);
                el.exit();
            }
        }
    }

    fn window_event(&mut self, el: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        match event {
            WindowEvent::CloseRequested => el.exit(),
            WindowEvent::KeyboardInput { event, .. }
                if event.state == ElementState::Pressed
                    && (matches!(event.logical_key, Key::Named(NamedKey::Escape))
                        || event.logical_key == Key::Character("q".into())) =>
            {
                el.exit();
            }
            WindowEvent::Resized(size) => {
                if let Some(st) = self.state.as_mut() {
                    st.resize(size);
                }
            }
            WindowEvent::RedrawRequested => {
                if let Err(e) = self.redraw() {
                    self.error = Some(e);
                    el.exit();
                }
            }
            _ => {}
        }
    }

    fn about_to_wait(&mut self, el: &ActiveEventLoop) {
        if let Some(limit) = self.opts.close_after
            && self.started.elapsed() >= limit
        {
            el.exit();
            return;
        }
        if let Some(st) = &self.state {
            st.window.request_redraw();
        }
        // With vsync, presenting paces the loop; without, wait for the next frame time.
        el.set_control_flow(if self.opts.vsync {
            ControlFlow::Poll
        } else {
            ControlFlow::WaitUntil(self.next_frame)
        });
    }
}

/// On Linux, an error when there is no X or Wayland display to open a window on.
pub(crate) fn check_display() -> Result<()> {
    if std::env::var_os("DISPLAY").is_none()
        && std::env::var_os("WAYLAND_DISPLAY").is_none()
        && cfg!(target_os = "linux")
    {
        return Err(DisplayError::NoDisplay(
            "neither DISPLAY nor WAYLAND_DISPLAY is set".into(),
        ));
    }
    Ok(())
}

/// Opens the window and shows `source`'s frames until it is closed (or `close_after`).
pub fn run_window(opts: DisplayOptions, source: Box<dyn FrameSource>) -> Result<()> {
    check_display()?;
    let mut builder = EventLoop::builder();
    #[cfg(target_os = "linux")]
    {
        use winit::platform::x11::EventLoopBuilderExtX11;
        builder.with_any_thread(true);
    }
    let event_loop = builder
        .build()
        .map_err(|e| DisplayError::NoDisplay(e.to_string()))?;
    let now = Instant::now();
    let device = source.device();
    let mut app = App {
        opts,
        device,
        source,
        state: None,
        error: None,
        started: now,
        next_frame: now,
        presented: 0,
        pending: None,
    };
    event_loop
        .run_app(&mut app)
        .map_err(|e| DisplayError::Window(e.to_string()))?;
    match app.error {
        Some(e) => Err(e),
        None => Ok(()),
    }
}
