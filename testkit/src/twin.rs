//! The digital twin on loopback, for the tests that drive it over its real wires: a twin of a
//! scenario serving SwarmCon on a TCP port, its robots' end on a UDP port (or a channel the test
//! opens), and optionally watching a frame server; run on its own thread in real time; and the
//! bridge's ends connected to it (pose source, robot link, a calibration rig).
use colcos_bridge::calibrate::{CalibrationRig, RawTracker};
use colcos_bridge::protocol::swarmcon::{FrameTransform, HeaderForm};
use colcos_bridge::transport::FrameServer;
use colcos_bridge::twin::{ByteChannel, CameraModel, TrackerServer, Twin, UdpChannel};
use colcos_bridge::{PoseSource, RobotLink, SourceOptions, open_pose_source, open_robot_link};
use colcos_sim::scenario::Scenario;
use std::net::SocketAddr;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, MutexGuard};
use std::thread::JoinHandle;

/// A UDP channel on a loopback port for the twin's robots, and the robot link URL that reaches it.
pub fn udp_channel() -> (Box<dyn ByteChannel>, String) {
    let channel = UdpChannel::bind("127.0.0.1:0").expect("a loopback UDP port");
    let url = format!("udp://{}", channel.local_addr().expect("its address"));
    (Box::new(channel), url)
}

/// The real-time runs of a test binary, one at a time: their timing bounds hold for a loop that has
/// a core to itself, not for several at once.
pub fn one_at_a_time() -> MutexGuard<'static, ()> {
    static TURN: Mutex<()> = Mutex::new(());
    TURN.lock().unwrap_or_else(|e| e.into_inner())
}

/// The bridge's pose source on the twin's SwarmCon stream at `tracker`, in `host`'s arena frame.
pub fn pose_source(tracker: SocketAddr, host: &Scenario) -> Box<dyn PoseSource> {
    let opts = SourceOptions::new(FrameTransform::new(host.arena_size().y as f64));
    open_pose_source(&format!("swarmcon://{tracker}"), &opts).expect("the twin's tracker stream")
}

/// A twin of a scenario on loopback ports, not yet running: set its camera, delays or faults
/// through [`Self::twin`], then [`Self::spawn`] it or step it by hand.
pub struct LoopbackTwin {
    pub twin: Twin,
    /// Where it serves SwarmCon.
    pub tracker_addr: SocketAddr,
    /// The robot link URL that reaches its robots.
    pub link_url: String,
    /// The frame server it watches (its robots' colour readings come from the frames shown there),
    /// when asked for.
    pub frames: Option<FrameServer>,
}

impl LoopbackTwin {
    /// A twin of `sc` whose robots answer over UDP, watching a frame server when `frames`.
    pub fn udp(sc: &Scenario, frames: bool) -> LoopbackTwin {
        Self::try_udp(sc, frames).expect("a twin of the scenario")
    }

    /// As [`Self::udp`], with the twin's refusal of the scenario as an error.
    pub fn try_udp(sc: &Scenario, frames: bool) -> colcos_sim::error::Result<LoopbackTwin> {
        let (channel, url) = udp_channel();
        Self::try_over(sc, channel, url, frames)
    }

    /// A twin of `sc` whose robots answer over `channel`, reached at `link_url`.
    pub fn over(
        sc: &Scenario,
        channel: Box<dyn ByteChannel>,
        link_url: String,
        frames: bool,
    ) -> LoopbackTwin {
        Self::try_over(sc, channel, link_url, frames).expect("a twin of the scenario")
    }

    /// As [`Self::over`], with the twin's refusal of the scenario as an error.
    pub fn try_over(
        sc: &Scenario,
        channel: Box<dyn ByteChannel>,
        link_url: String,
        frames: bool,
    ) -> colcos_sim::error::Result<LoopbackTwin> {
        let tracker = TrackerServer::bind("127.0.0.1:0", HeaderForm::Updated)
            .expect("a loopback TCP port for the tracker");
        let tracker_addr = tracker.local_addr();
        let frames = frames.then(|| FrameServer::bind("127.0.0.1:0").expect("a loopback TCP port"));
        let twin = Twin::new(
            sc,
            tracker,
            channel,
            frames.as_ref().map(FrameServer::local_addr),
        )?;
        Ok(LoopbackTwin {
            twin,
            tracker_addr,
            link_url,
            frames,
        })
    }

    /// Runs the twin on its own thread in real time for at most `seconds`.
    pub fn spawn(self, seconds: f64) -> RunningTwin {
        let stop = Arc::new(AtomicBool::new(false));
        let handle = {
            let stop = stop.clone();
            let mut twin = self.twin;
            std::thread::spawn(move || {
                twin.run(Some(seconds), &stop);
                twin
            })
        };
        RunningTwin {
            handle,
            stop,
            tracker_addr: self.tracker_addr,
            link_url: self.link_url,
            frames: self.frames,
        }
    }
}

/// A twin running on its own thread, and the ends the bridge connects to.
pub struct RunningTwin {
    handle: JoinHandle<Twin>,
    stop: Arc<AtomicBool>,
    pub tracker_addr: SocketAddr,
    pub link_url: String,
    /// The frame server it watches, for the bridge to show frames on (take it).
    pub frames: Option<FrameServer>,
}

impl RunningTwin {
    /// The bridge's pose source on its SwarmCon stream, in `host`'s arena frame.
    pub fn pose_source(&self, host: &Scenario) -> Box<dyn PoseSource> {
        pose_source(self.tracker_addr, host)
    }

    /// The bridge's robot link to its robots.
    pub fn robot_link(&self) -> Box<dyn RobotLink> {
        open_robot_link(&self.link_url).expect("the twin's robot link")
    }

    /// Waits for its run to end and hands it back.
    pub fn join(self) -> Twin {
        self.handle.join().expect("the twin's thread")
    }

    /// Stops it now and hands it back.
    pub fn stop(self) -> Twin {
        self.stop.store(true, Ordering::Relaxed);
        self.join()
    }
}

/// A twin and a calibration rig connected to it, side by side over loopback.
pub struct TwinRun {
    pub rig: CalibrationRig,
    pub tracker_addr: SocketAddr,
    twin: RunningTwin,
}

impl TwinRun {
    /// Starts a twin of `sc` (seen through `camera` if given, its tracker blocks held back by
    /// `latency` +- `jitter` s) for at most `seconds`, and a calibration rig connected to it.
    pub fn start(
        sc: &Scenario,
        camera: Option<CameraModel>,
        latency: f64,
        jitter: f64,
        seconds: f64,
    ) -> TwinRun {
        let mut twin = LoopbackTwin::udp(sc, true);
        twin.twin.tracker().set_delay(latency, jitter, 11);
        twin.twin.set_camera(camera, 3);
        let mut twin = twin.spawn(seconds);
        let tracker =
            RawTracker::connect(&twin.tracker_addr.to_string()).expect("the twin's tracker stream");
        let link = twin.robot_link();
        let frames = twin.frames.take().expect("a frame server");
        TwinRun {
            rig: CalibrationRig::new(tracker, frames, Some(link)),
            tracker_addr: twin.tracker_addr,
            twin,
        }
    }

    /// Stops the twin and hands it back.
    pub fn stop(self) -> Twin {
        self.twin.stop()
    }
}
