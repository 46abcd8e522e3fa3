//! The calibrations run over the rig's own wires: the tracker's SwarmCon stream read raw (the
//! unidentified `-01` slots are the fiducials), patterns shown through the frame stream (the
//! display), and the robots driven and asked for telemetry over their link.
use super::CalibrationError;
use crate::protocol::colias::{BROADCAST_ID, CommandPacket, HostCommand};
use crate::protocol::swarmcon::{SlotState, StreamParser, TrackerFrame, TrackerMessage};
use crate::transport::FrameServer;
use crate::transport::RobotLink;
use image::RgbImage;
use std::io::Read;
use std::net::{TcpStream, ToSocketAddrs};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// Most blocks kept between two reads of [`RawTracker::take`].
const MAX_KEPT: usize = 10_000;

/// A SwarmCon stream read on a thread of its own: every block with the moment it arrived.
pub struct RawTracker {
    blocks: Arc<Mutex<Vec<(f64, TrackerFrame)>>>,
    stop: Arc<AtomicBool>,
}

impl RawTracker {
    /// Connects to a SwarmCon position server at `addr` (`HOST:PORT`).
    pub fn connect(addr: &str) -> Result<RawTracker, CalibrationError> {
        let target = addr
            .to_socket_addrs()
            .ok()
            .and_then(|mut a| a.next())
            .ok_or_else(|| CalibrationError::Run(format!("--tracker `{addr}`: not an address")))?;
        let mut stream = TcpStream::connect_timeout(&target, Duration::from_secs(2))
            .map_err(|e| CalibrationError::Run(format!("--tracker {addr}: {e}")))?;
        let _ = stream.set_nodelay(true);
        let _ = stream.set_read_timeout(Some(Duration::from_millis(20)));
        let blocks = Arc::new(Mutex::new(Vec::new()));
        let stop = Arc::new(AtomicBool::new(false));
        let (b, s) = (blocks.clone(), stop.clone());
        std::thread::Builder::new()
            .name("calibrate-tracker".into())
            .spawn(move || {
                let mut parser = StreamParser::new();
                let mut buf = vec![0u8; 64 * 1024];
                let mut out = Vec::new();
                while !s.load(Ordering::Relaxed) {
                    match stream.read(&mut buf) {
                        Ok(0) => break,
                        Ok(n) => {
                            let receipt = crate::transport::epoch_s();
                            parser.feed_into(&buf[..n], &mut out);
                            if let Ok(mut b) = b.lock() {
                                for m in out.drain(..) {
                                    if let TrackerMessage::Frame(f) = m {
                                        b.push((receipt, f));
                                    }
                                }
                                let excess = b.len().saturating_sub(MAX_KEPT);
                                b.drain(..excess);
                            }
                        }
                        Err(e)
                            if matches!(
                                e.kind(),
                                std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut
                            ) => {}
                        Err(_) => break,
                    }
                }
            })
            .map_err(|e| CalibrationError::Run(e.to_string()))?;
        Ok(RawTracker { blocks, stop })
    }

    /// The blocks that arrived since the last call: (receipt, host epoch s; the block).
    pub fn take(&self) -> Vec<(f64, TrackerFrame)> {
        self.blocks
            .lock()
            .map(|mut b| std::mem::take(&mut *b))
            .unwrap_or_default()
    }
}

impl Drop for RawTracker {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
    }
}

/// The unidentified (`-01`) slots of a block, seen in its frame: fiducials.
pub(crate) fn fiducials_in(frame: &TrackerFrame) -> Vec<[f64; 2]> {
    frame
        .robots
        .iter()
        .filter(|s| s.id == -1 && s.state == SlotState::Fresh)
        .map(|s| [s.x, s.y])
        .collect()
}

/// Robot `id`'s slot in a block when it was seen in that frame: (x, y, yaw_deg).
pub(crate) fn fresh_slot(frame: &TrackerFrame, id: i32) -> Option<(f64, f64, f64)> {
    frame
        .robots
        .iter()
        .find(|s| s.id == id && s.state == SlotState::Fresh)
        .map(|s| (s.x, s.y, s.yaw_deg))
}

/// What a calibration talks to: the tracker, the display's frame stream, and (for the steps that
/// drive or read robots) the radio link.
pub struct CalibrationRig {
    pub tracker: RawTracker,
    pub frames: FrameServer,
    pub link: Option<Box<dyn RobotLink>>,
    start: Instant,
}

impl CalibrationRig {
    pub fn new(
        tracker: RawTracker,
        frames: FrameServer,
        link: Option<Box<dyn RobotLink>>,
    ) -> CalibrationRig {
        CalibrationRig {
            tracker,
            frames,
            link,
            start: Instant::now(),
        }
    }

    /// Shows `frame` (sent to every subscriber of the frame stream).
    pub fn show(&mut self, frame: &RgbImage) {
        self.frames
            .publish(frame, self.start.elapsed().as_secs_f64());
    }

    /// Waits until the frame stream has a subscriber (the display, or the twin).
    pub fn wait_for_display(&self, timeout: Duration) -> Result<(), CalibrationError> {
        let until = Instant::now() + timeout;
        while self.frames.subscribers() == 0 {
            if Instant::now() > until {
                return Err(CalibrationError::Run(format!(
                    "nothing subscribed to the frame stream on {} within {:.0} s: start the display (or the twin with --frames)",
                    self.frames.local_addr(),
                    timeout.as_secs_f64()
                )));
            }
            std::thread::sleep(Duration::from_millis(20));
        }
        Ok(())
    }

    fn t_ms(&self) -> u32 {
        self.start.elapsed().as_millis() as u32
    }

    fn link(&mut self) -> Result<&mut Box<dyn RobotLink>, CalibrationError> {
        self.link
            .as_mut()
            .ok_or_else(|| CalibrationError::Run("this step drives robots: give --robots".into()))
    }

    /// Sends `command` to radio `id` and pushes it out.
    pub fn command(&mut self, id: u8, command: HostCommand) -> Result<(), CalibrationError> {
        let t = self.t_ms();
        let link = self.link()?;
        link.send(CommandPacket::new(id, t, command));
        link.pump()
            .map(|_| ())
            .map_err(|e| CalibrationError::Run(format!("robot link: {e}")))
    }

    /// Drives radio `id` with wheel speeds for `seconds`, re-sending every 50 ms (the firmware's
    /// keep-alive), collecting tracker blocks meanwhile; then stops it.
    pub fn drive(
        &mut self,
        id: u8,
        left: f32,
        right: f32,
        seconds: f64,
        blocks: &mut Vec<(f64, TrackerFrame)>,
    ) -> Result<(), CalibrationError> {
        let until = Instant::now() + Duration::from_secs_f64(seconds);
        while Instant::now() < until {
            self.command(id, HostCommand::WheelSpeeds { left, right })?;
            std::thread::sleep(Duration::from_millis(50));
            blocks.extend(self.tracker.take());
        }
        self.stop_all()
    }

    /// Stops every robot (broadcast).
    pub fn stop_all(&mut self) -> Result<(), CalibrationError> {
        let t = self.t_ms();
        let link = self.link()?;
        link.stop_now(CommandPacket::new(
            BROADCAST_ID,
            t,
            HostCommand::WheelSpeeds {
                left: 0.0,
                right: 0.0,
            },
        ))
        .map_err(|e| CalibrationError::Run(format!("robot link: {e}")))
    }
}

impl Drop for CalibrationRig {
    fn drop(&mut self) {
        if self.link.is_some() {
            let _ = self.stop_all();
        }
    }
}
