//! The rig run's GIF, as `colcos run` writes one: frames drawn in the loop (the screen with the robots
//! at their tracked poses, a legend of the groups), encoded on a thread of their own so that the
//! encoder never holds the loop up; a frame that finds the encoder busy is dropped and counted. A rig
//! run's length is not known ahead, so rather than thinning, the GIF keeps its first [`MAX_FRAMES`].
use colcos_sim::error::Result;
use colcos_sim::output::gif::GifRecorder;
use image::RgbImage;
use std::path::Path;
use std::sync::mpsc::{SyncSender, TrySendError, sync_channel};
use std::thread::JoinHandle;

/// At most this many frames (as `colcos run` keeps): 8 minutes at the default 0.5 s interval.
pub(crate) const MAX_FRAMES: u64 = 1000;

pub(crate) struct GifThread {
    frames: Option<SyncSender<RgbImage>>,
    handle: Option<JoinHandle<()>>,
    pub size: (u32, u32),
    pub interval: f64,
    pub dropped: u64,
    pushed: u64,
}

impl GifThread {
    pub(crate) fn start(
        path: &Path,
        screen: &colcos_sim::screen::ScreenSpec,
        width: u32,
        interval: f64,
    ) -> Result<GifThread> {
        let mut gif = GifRecorder::for_screen(path, screen, width, interval as f32)?;
        let size = gif.size();
        let (tx, rx) = sync_channel::<RgbImage>(8);
        let handle = std::thread::Builder::new()
            .name("colcos-gif".into())
            .spawn(move || {
                for img in rx {
                    if let Err(e) = gif.image(img) {
                        log::warn!("run.gif: {e}; no more frames");
                        break;
                    }
                }
            })
            .map_err(|e| colcos_sim::error::SimError::io("starting the GIF encoder", e))?;
        Ok(GifThread {
            frames: Some(tx),
            handle: Some(handle),
            size,
            interval,
            dropped: 0,
            pushed: 0,
        })
    }

    pub(crate) fn push(&mut self, img: RgbImage) {
        if self.pushed == MAX_FRAMES {
            log::info!("run.gif holds the run's first {MAX_FRAMES} frames");
            self.frames = None;
        }
        if let Some(tx) = &self.frames {
            self.pushed += 1;
            match tx.try_send(img) {
                Ok(()) => {}
                Err(TrySendError::Full(_)) => self.dropped += 1,
                Err(TrySendError::Disconnected(_)) => self.frames = None,
            }
        }
    }
}

impl Drop for GifThread {
    /// Ends the GIF: the encoder takes the frames still queued and closes the file.
    fn drop(&mut self) {
        self.frames = None;
        if let Some(h) = self.handle.take() {
            let _ = h.join();
        }
    }
}
