//! The twin and a calibration rig side by side over loopback, for the calibration tests.
// Each test file uses part of this.
#![allow(dead_code)]

use colcos_bridge::calibrate::{CalibrationRig, RawTracker};
use colcos_bridge::open_robot_link;
use colcos_bridge::protocol::swarmcon::HeaderForm;
use colcos_bridge::transport::FrameServer;
use colcos_bridge::twin::{CameraModel, TrackerServer, Twin, UdpChannel};
use colcos_sim::scenario::Scenario;
use std::net::SocketAddr;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

/// A scenario on the paper's panel with robots parked at `poses` (x, y, heading in degrees) and
/// `rig` as the `[rig]` section's body.
pub fn scenario(poses: &[(f64, f64, f64)], rig: &str) -> Scenario {
    let list: Vec<String> = poses
        .iter()
        .map(|(x, y, h)| format!("[{x}, {y}, {h}]"))
        .collect();
    Scenario::from_toml_str(&toml_text(rig, [3840, 2160], &list), ".").unwrap()
}

fn toml_text(rig: &str, resolution: [u32; 2], poses: &[String]) -> String {
    format!(
        r#"
name = "calibration"
duration = 60.0
seed = 5
[screen]
resolution = [{}, {}]
[[pheromones]]
name = "a"
colour = [0, 255, 0]
model = "gaussian"
evaporation = 5.0
[[robots]]
count = {}
behaviour = "wander"
placement = "explicit"
poses = [{}]
[rig]
{rig}
"#,
        resolution[0],
        resolution[1],
        poses.len(),
        poses.join(", ")
    )
}

/// One parked robot at the panel's centre, on a screen of `resolution`.
pub fn scenario_with_screen(rig: &str, resolution: [u32; 2]) -> Scenario {
    Scenario::from_toml_str(
        &toml_text(rig, resolution, &["[0.72, 0.4, 0.0]".into()]),
        ".",
    )
    .unwrap()
}

pub struct TwinRun {
    pub rig: CalibrationRig,
    pub tracker_addr: SocketAddr,
    twin: Option<std::thread::JoinHandle<Twin>>,
    stop: Arc<AtomicBool>,
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
        let mut tracker = TrackerServer::bind("127.0.0.1:0", HeaderForm::Updated).unwrap();
        tracker.set_delay(latency, jitter, 11);
        let tracker_addr = tracker.local_addr();
        let frames = FrameServer::bind("127.0.0.1:0").unwrap();
        let channel = UdpChannel::bind("127.0.0.1:0").unwrap();
        let link_url = format!("udp://{}", channel.local_addr().unwrap());
        let mut twin =
            Twin::new(sc, tracker, Box::new(channel), Some(frames.local_addr())).unwrap();
        twin.set_camera(camera, 3);
        let stop = Arc::new(AtomicBool::new(false));
        let s = stop.clone();
        let handle = std::thread::spawn(move || {
            twin.run(Some(seconds), &s);
            twin
        });
        let tracker = RawTracker::connect(&tracker_addr.to_string()).unwrap();
        let link = open_robot_link(&link_url).unwrap();
        TwinRun {
            rig: CalibrationRig::new(tracker, frames, Some(link)),
            tracker_addr,
            twin: Some(handle),
            stop,
        }
    }

    /// Stops the twin and hands it back.
    pub fn stop(mut self) -> Twin {
        self.stop.store(true, Ordering::Relaxed);
        self.twin.take().unwrap().join().unwrap()
    }
}

/// Six robots wandering at `speed` m/s on the paper's panel, tracked every 20 ms step without a
/// delay of the tracker model's own.
pub fn wanderers(speed: f64) -> Scenario {
    let text = format!(
        r#"
name = "wanderers"
duration = 60.0
seed = 8
[tracker]
rate_hz = 50
latency = 0.0
dropout = 0.0
[[pheromones]]
name = "a"
colour = [0, 255, 0]
model = "gaussian"
evaporation = 5.0
[[robots]]
count = 6
behaviour = "wander"
params = {{ speed = {speed} }}
placement = "grid"
region = [0.2, 0.2, 1.2, 0.6]
"#
    );
    Scenario::from_toml_str(&text, ".").unwrap()
}
