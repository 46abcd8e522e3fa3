//! A window and its surface: opened on a chosen monitor, presenting with the source's device when it
//! can, else with its own.
use crate::{
    DisplayError, DisplayOptions, Frame, Presenter, Result, SharedDevice, instance, map_read,
};
use std::sync::Arc;
use winit::event_loop::ActiveEventLoop;
use winit::window::{Fullscreen, Window};

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
    log::info!("colcos-display: monitors [{names}]");
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
        log::info!(
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
    log::info!(
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
    map_read(&dev.device, &staging)?;
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
