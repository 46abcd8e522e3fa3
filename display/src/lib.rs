//! colcos-display: the screen image of eq. (1) in a window (winit 0.30 + wgpu), full screen on a chosen
//! monitor or windowed, refreshed at the field's rate with vsync; and headless rendering of the same
//! image, through the same pipeline, to PNG.
//!
//! The image is shown pixel for pixel when the window has its size, otherwise scaled by the largest
//! factor that fits (nearest neighbour, aspect kept, black bars). Colours are written to a non-sRGB
//! target, so the 8-bit levels of eq. (1) reach the panel unchanged.
use std::time::Duration;

mod headless;
mod presenter;
mod run;
mod viewer;
mod window;

pub use headless::{render_headless, render_headless_frame};
pub use presenter::Presenter;
pub use run::run_window;
pub use viewer::Viewer;
/// The wgpu this crate is built on (for [`SharedDevice`] and [`Frame::Buffer`]).
pub use wgpu;

pub(crate) use run::check_display;
pub(crate) use window::{WindowState, open_window};

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

/// A wgpu instance with the backends and flags the environment asks for.
pub(crate) fn instance() -> wgpu::Instance {
    wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env())
}

/// Maps `buffer` (on `device`) for reading, blocking until it is mapped.
pub(crate) fn map_read(device: &wgpu::Device, buffer: &wgpu::Buffer) -> Result<()> {
    let (tx, rx) = std::sync::mpsc::channel();
    buffer.map_async(wgpu::MapMode::Read, .., move |r| {
        let _ = tx.send(r);
    });
    device
        .poll(wgpu::PollType::wait_indefinitely())
        .map_err(|e| DisplayError::Gpu(e.to_string()))?;
    rx.recv()
        .map_err(|e| DisplayError::Gpu(e.to_string()))?
        .map_err(|e| DisplayError::Gpu(e.to_string()))
}
