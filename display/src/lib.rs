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

/// Supplies the images to show.
pub trait FrameSource {
    /// Image size, pixels.
    fn size(&self) -> (u32, u32);
    /// The next image (RGBA8, row 0 at the top), called once per frame period; `None` keeps the last
    /// one on screen (a finished or paused run).
    fn next_frame(&mut self) -> Option<Vec<u8>>;
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
    fn next_frame(&mut self) -> Option<Vec<u8>> {
        if self.1 {
            return None;
        }
        self.1 = true;
        Some(self.0.as_raw().clone())
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

    /// Uploads an RGBA8 image of `size` (replacing the texture when the size changes).
    pub fn upload(&mut self, rgba: &[u8], size: (u32, u32)) {
        if size != self.size {
            let (t, b) = Self::make_texture(&self.device, &self.layout, &self.uniform, size);
            self.texture = t;
            self.bind = b;
            self.size = size;
        }
        if size.0 == 0 || size.1 == 0 {
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
    let format = wgpu::TextureFormat::Rgba8Unorm;
    let mut p = Presenter::new(device.clone(), queue.clone(), format, img.dimensions());
    p.upload(img.as_raw(), img.dimensions());
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

struct WindowState {
    window: Arc<Window>,
    surface: wgpu::Surface<'static>,
    config: wgpu::SurfaceConfiguration,
    presenter: Presenter,
}

struct App {
    opts: DisplayOptions,
    source: Box<dyn FrameSource>,
    state: Option<WindowState>,
    error: Option<DisplayError>,
    started: Instant,
    next_frame: Instant,
    presented: u64,
    /// The latest image, kept until the window exists.
    pending: Option<Vec<u8>>,
}

impl App {
    fn open(&mut self, el: &ActiveEventLoop) -> Result<WindowState> {
        let monitors: Vec<_> = el.available_monitors().collect();
        let names = monitors
            .iter()
            .enumerate()
            .map(|(i, m)| format!("{i}: {} {:?}", m.name().unwrap_or_default(), m.size()))
            .collect::<Vec<_>>()
            .join(", ");
        let monitor = match self.opts.monitor {
            Some(i) => Some(monitors.get(i).cloned().ok_or(DisplayError::NoMonitor {
                index: i,
                count: monitors.len(),
                names: names.clone(),
            })?),
            None => el.primary_monitor().or_else(|| monitors.first().cloned()),
        };
        eprintln!("colcos-display: monitors [{names}]");
        let size = self.opts.window_size.unwrap_or(self.source.size());
        let mut attrs = Window::default_attributes().with_title(self.opts.title.clone());
        if self.opts.fullscreen {
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
                .with_inner_size(winit::dpi::PhysicalSize::new(size.0.max(1), size.1.max(1)))
                .with_decorations(self.opts.decorations)
                .with_resizable(true);
            if let Some((x, y)) = self.opts.position {
                attrs = attrs.with_position(winit::dpi::PhysicalPosition::new(x, y));
            }
        }
        let window = Arc::new(
            el.create_window(attrs)
                .map_err(|e| DisplayError::Window(e.to_string()))?,
        );
        let inst = instance();
        let surface = inst
            .create_surface(window.clone())
            .map_err(|e| DisplayError::Gpu(e.to_string()))?;
        let adapter = pollster::block_on(inst.request_adapter(&wgpu::RequestAdapterOptions {
            compatible_surface: Some(&surface),
            ..Default::default()
        }))
        .map_err(|e| DisplayError::NoAdapter(e.to_string()))?;
        eprintln!(
            "colcos-display: adapter {} ({:?}, {:?})",
            adapter.get_info().name,
            adapter.get_info().device_type,
            adapter.get_info().backend
        );
        let (device, queue) =
            pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor::default()))
                .map_err(|e| DisplayError::Gpu(e.to_string()))?;
        let inner = window.inner_size();
        let mut config = surface
            .get_default_config(&adapter, inner.width.max(1), inner.height.max(1))
            .ok_or_else(|| {
                DisplayError::Gpu("the surface is not supported by the adapter".into())
            })?;
        let caps = surface.get_capabilities(&adapter);
        // A non-sRGB format, so the 8-bit levels are shown as they are.
        if let Some(f) = caps.formats.iter().find(|f| !f.is_srgb()) {
            config.format = *f;
        } else {
            config.view_formats = vec![config.format.remove_srgb_suffix()];
        }
        config.present_mode = if self.opts.vsync {
            wgpu::PresentMode::Fifo
        } else if caps.present_modes.contains(&wgpu::PresentMode::Immediate) {
            wgpu::PresentMode::Immediate
        } else {
            wgpu::PresentMode::AutoNoVsync
        };
        surface.configure(&device, &config);
        let view_format = config.format.remove_srgb_suffix();
        let presenter = Presenter::new(device, queue, view_format, self.source.size());
        Ok(WindowState {
            window,
            surface,
            config,
            presenter,
        })
    }

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
            st.presenter.upload(&f, size);
        }
        let frame = match st.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(t)
            | wgpu::CurrentSurfaceTexture::Suboptimal(t) => t,
            wgpu::CurrentSurfaceTexture::Timeout | wgpu::CurrentSurfaceTexture::Occluded => {
                return Ok(());
            }
            _ => {
                st.surface.configure(&st.presenter.device, &st.config);
                return Ok(());
            }
        };
        let view = frame.texture.create_view(&wgpu::TextureViewDescriptor {
            format: Some(st.config.format.remove_srgb_suffix()),
            ..Default::default()
        });
        let mut enc = st
            .presenter
            .device
            .create_command_encoder(&Default::default());
        st.presenter
            .draw(&mut enc, &view, (st.config.width, st.config.height));
        st.presenter.queue.submit([enc.finish()]);
        st.window.pre_present_notify();
        st.presenter.queue.present(frame);
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
        match self.open(el) {
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
                    st.config.width = size.width.max(1);
                    st.config.height = size.height.max(1);
                    st.surface.configure(&st.presenter.device, &st.config);
                    st.window.request_redraw();
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

/// Opens the window and shows `source`'s frames until it is closed (or `close_after`).
pub fn run_window(opts: DisplayOptions, source: Box<dyn FrameSource>) -> Result<()> {
    if std::env::var_os("DISPLAY").is_none()
        && std::env::var_os("WAYLAND_DISPLAY").is_none()
        && cfg!(target_os = "linux")
    {
        return Err(DisplayError::NoDisplay(
            "neither DISPLAY nor WAYLAND_DISPLAY is set".into(),
        ));
    }
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
    let mut app = App {
        opts,
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
