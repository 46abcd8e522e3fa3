//! The event loop of [`run_window`]: one window showing a [`FrameSource`]'s images at its frame period.
use crate::{DisplayError, DisplayOptions, Frame, FrameSource, Result, SharedDevice};
use crate::{WindowState, open_window};
use std::time::Instant;
use winit::application::ApplicationHandler;
use winit::event::{ElementState, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::keyboard::{Key, NamedKey};
use winit::window::WindowId;

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
