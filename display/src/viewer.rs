//! A window fed from the caller's thread, for `render_mode="human"` in the Python environments: the
//! caller hands images to [`Viewer::show`] (which paces them to the frame period) and goes on; a
//! display thread owns the winit event loop and presents them.
//!
//! winit allows one event loop per process, created once: the first [`Viewer::open`] starts the
//! display thread, which then lives as long as the process and serves every viewer (windows are
//! opened and closed through it). On Linux it needs X11 or Wayland (`DISPLAY` / `WAYLAND_DISPLAY`;
//! Xvfb works); on macOS, where winit wants the main thread, viewers are not available.
use crate::{DisplayError, DisplayOptions, Frame, Result, WindowState, check_display, open_window};
use std::collections::HashMap;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::mpsc;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};
use winit::application::ApplicationHandler;
use winit::event::{ElementState, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop, EventLoopProxy};
use winit::keyboard::{Key, NamedKey};
use winit::window::WindowId;

/// An RGBA8 image and its size.
type Image = (Vec<u8>, (u32, u32));

/// What a viewer and its window share.
#[derive(Default)]
struct Slot {
    /// The latest image not yet put on screen (a newer one replaces it).
    frame: Mutex<Option<Image>>,
    presented: AtomicU64,
    /// Cleared when the window is closed (by the user or [`Viewer::close`]).
    open: AtomicBool,
}

enum Cmd {
    Open {
        id: u64,
        opts: Box<DisplayOptions>,
        size: (u32, u32),
        slot: Arc<Slot>,
        reply: mpsc::Sender<Result<()>>,
    },
    Frame {
        id: u64,
    },
    Close {
        id: u64,
        reply: mpsc::Sender<()>,
    },
}

type Proxy = EventLoopProxy<Cmd>;

/// The display thread's proxy once started, or why it could not start.
static LOOP: Mutex<Option<std::result::Result<Proxy, String>>> = Mutex::new(None);
static NEXT_ID: AtomicU64 = AtomicU64::new(1);

fn proxy() -> Result<Proxy> {
    let mut g = LOOP.lock().unwrap_or_else(|p| p.into_inner());
    if let Some(r) = &*g {
        return r.clone().map_err(DisplayError::NoDisplay);
    }
    // Checked before the (one-shot) event loop is spent on a display that is not there.
    check_display()?;
    let (tx, rx) = mpsc::channel();
    std::thread::Builder::new()
        .name("colcos-display".into())
        .spawn(move || {
            let mut builder = EventLoop::<Cmd>::with_user_event();
            #[cfg(target_os = "linux")]
            {
                use winit::platform::x11::EventLoopBuilderExtX11;
                builder.with_any_thread(true);
            }
            match builder.build() {
                Err(e) => {
                    let _ = tx.send(Err(e.to_string()));
                }
                Ok(el) => {
                    let _ = tx.send(Ok(el.create_proxy()));
                    el.set_control_flow(ControlFlow::Wait);
                    let mut app = ViewerApp::default();
                    if let Err(e) = el.run_app(&mut app) {
                        log::error!("colcos-display: the display thread stopped: {e}");
                    }
                }
            }
        })
        .map_err(|e| DisplayError::Window(format!("cannot start the display thread: {e}")))?;
    let r = rx
        .recv()
        .unwrap_or_else(|_| Err("the display thread ended at once".into()));
    *g = Some(r.clone());
    r.map_err(DisplayError::NoDisplay)
}

/// A window showing the images given to [`Viewer::show`]; closed by [`Viewer::close`] or on drop.
pub struct Viewer {
    id: u64,
    proxy: Proxy,
    slot: Arc<Slot>,
    period: Duration,
    next: Option<Instant>,
}

impl Viewer {
    /// Opens a window for images of `size` (see [`DisplayOptions`]; `frame_period` paces
    /// [`Viewer::show`], `close_after` and `announce_first_frame` are not used). Blocks until the
    /// window exists, or says why it cannot.
    pub fn open(opts: DisplayOptions, size: (u32, u32)) -> Result<Viewer> {
        let proxy = proxy()?;
        let id = NEXT_ID.fetch_add(1, Ordering::Relaxed);
        let slot = Arc::new(Slot::default());
        slot.open.store(true, Ordering::SeqCst);
        let (tx, rx) = mpsc::channel();
        let period = opts.frame_period;
        proxy
            .send_event(Cmd::Open {
                id,
                opts: Box::new(opts),
                size,
                slot: slot.clone(),
                reply: tx,
            })
            .map_err(|_| DisplayError::Window("the display thread has stopped".into()))?;
        rx.recv_timeout(Duration::from_secs(60))
            .map_err(|_| DisplayError::Window("the window did not open within 60 s".into()))??;
        Ok(Viewer {
            id,
            proxy,
            slot,
            period,
            next: None,
        })
    }

    /// Shows an RGBA8 image of `size` (row 0 at the top). Waits first, if need be, so that images are
    /// shown at most once per frame period (the field's rate); does not wait for the screen. Returns
    /// false (and shows nothing) once the window is closed.
    pub fn show(&mut self, rgba: Vec<u8>, size: (u32, u32)) -> bool {
        if !self.is_open() {
            return false;
        }
        let now = Instant::now();
        let due = self.next.unwrap_or(now);
        if due > now {
            std::thread::sleep(due - now);
        }
        self.next = Some(due.max(now) + self.period);
        *self.slot.frame.lock().unwrap_or_else(|p| p.into_inner()) = Some((rgba, size));
        if self.proxy.send_event(Cmd::Frame { id: self.id }).is_err() {
            self.slot.open.store(false, Ordering::SeqCst);
            return false;
        }
        true
    }

    /// Whether the window is still open (the user may close it).
    pub fn is_open(&self) -> bool {
        self.slot.open.load(Ordering::SeqCst)
    }

    /// Frames presented so far.
    pub fn presented(&self) -> u64 {
        self.slot.presented.load(Ordering::SeqCst)
    }

    /// Closes the window (and waits, up to 5 s, until it is gone). Closing twice is harmless.
    pub fn close(&mut self) {
        if !self.slot.open.swap(false, Ordering::SeqCst) {
            return;
        }
        let (tx, rx) = mpsc::channel();
        if self
            .proxy
            .send_event(Cmd::Close {
                id: self.id,
                reply: tx,
            })
            .is_ok()
        {
            let _ = rx.recv_timeout(Duration::from_secs(5));
        }
    }
}

impl Drop for Viewer {
    fn drop(&mut self) {
        self.close();
    }
}

#[derive(Default)]
struct ViewerApp {
    windows: HashMap<u64, (WindowState, Arc<Slot>)>,
    ids: HashMap<WindowId, u64>,
}

impl ViewerApp {
    fn remove(&mut self, id: u64) {
        if let Some((st, slot)) = self.windows.remove(&id) {
            slot.open.store(false, Ordering::SeqCst);
            self.ids.remove(&st.window.id());
            st.window.set_visible(false);
        }
    }
}

impl ApplicationHandler<Cmd> for ViewerApp {
    fn resumed(&mut self, _el: &ActiveEventLoop) {}

    fn user_event(&mut self, el: &ActiveEventLoop, cmd: Cmd) {
        match cmd {
            Cmd::Open {
                id,
                opts,
                size,
                slot,
                reply,
            } => match open_window(el, &opts, size, None) {
                Ok(st) => {
                    self.ids.insert(st.window.id(), id);
                    st.window.request_redraw();
                    self.windows.insert(id, (st, slot));
                    let _ = reply.send(Ok(()));
                }
                Err(e) => {
                    let _ = reply.send(Err(e));
                }
            },
            Cmd::Frame { id } => {
                if let Some((st, slot)) = self.windows.get_mut(&id) {
                    let frame = slot.frame.lock().unwrap_or_else(|p| p.into_inner()).take();
                    if let Some((rgba, size)) = frame {
                        match st.set_frame(Frame::Rgba(rgba), size, None) {
                            Ok(()) => st.window.request_redraw(),
                            Err(e) => {
                                log::warn!("colcos-display: {e}; closing the window");
                                self.remove(id);
                            }
                        }
                    }
                }
            }
            Cmd::Close { id, reply } => {
                self.remove(id);
                let _ = reply.send(());
            }
        }
    }

    fn window_event(&mut self, _el: &ActiveEventLoop, wid: WindowId, event: WindowEvent) {
        let Some(&id) = self.ids.get(&wid) else {
            return;
        };
        match event {
            WindowEvent::CloseRequested => self.remove(id),
            WindowEvent::KeyboardInput { event, .. }
                if event.state == ElementState::Pressed
                    && (matches!(event.logical_key, Key::Named(NamedKey::Escape))
                        || event.logical_key == Key::Character("q".into())) =>
            {
                self.remove(id)
            }
            WindowEvent::Resized(size) => {
                if let Some((st, _)) = self.windows.get_mut(&id) {
                    st.resize(size);
                }
            }
            WindowEvent::RedrawRequested => {
                if let Some((st, slot)) = self.windows.get_mut(&id)
                    && st.present()
                {
                    slot.presented.fetch_add(1, Ordering::SeqCst);
                }
            }
            _ => {}
        }
    }
}
