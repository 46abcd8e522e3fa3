//! The digital twin: the simulator playing the rig over the rig's real wire formats. A SwarmCon
//! position server on TCP writes the tracker model's poses (noise, latency, dropouts, stale slots) in
//! the exact text format; the robots' end of the serial protocol (a pseudo-terminal or UDP) applies
//! the commands it receives to the simulated robots and answers data requests with telemetry whose
//! colour counts come from the frames the bridge displays. Faults on demand.
mod camera;
mod plant;
mod robot_end;
mod tracker_server;

pub use camera::{CameraModel, Noise, detect_fiducials};
pub use plant::{FIRMWARE_TIMEOUT, TwinArena};
pub use robot_end::{
    BUMPER_DARK, BUMPER_SPAN, ByteChannel, PtyChannel, Received, RobotEnd, RobotFaults, UdpChannel,
    bumper_reading, motion as legacy_motion_wheels,
};
pub use tracker_server::{TrackerFaults, TrackerServer};

use crate::onboard::{OnboardFirmware, OnboardFleet, OnboardManifest};
use crate::protocol::swarmcon::FrameTransform;
use crate::transport::FrameClient;
use colcos_sim::scenario::Scenario;
use std::net::SocketAddr;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

/// Fiducial centres (our frame, m) by the twin time they were first seen at.
type FiducialHistory = std::collections::VecDeque<(f64, Vec<[f64; 2]>)>;

pub struct Twin {
    arena: TwinArena,
    tracker: TrackerServer,
    robots: RobotEnd,
    frames: Option<FrameClient>,
    transform: FrameTransform,
    tracker_ids: Vec<i32>,
    /// The overhead camera, when one is modelled (calibration): poses go through it, and the
    /// fiducials in the frames the bridge shows are reported as unidentified (`-01`) slots.
    camera: Option<(CameraModel, Noise)>,
    /// Time of the frame the fiducials were last looked for in, and per twin time they were seen
    /// at, their centres (our frame, m): the calibration patterns (white discs on black) in the
    /// frames the bridge shows. Reported with the tracker frame captured at or after that time, so
    /// they come as late as the robots' poses do.
    fiducials: (f64, FiducialHistory),
    /// Twin time of the last block sent, s.
    last_block: f64,
    block_period: f64,
}

impl Twin {
    /// A twin of `scenario` serving poses on `tracker` and the robots' end on `channel`; colour
    /// readings from the frame stream at `frames` when given.
    pub fn new(
        scenario: &Scenario,
        tracker: TrackerServer,
        channel: Box<dyn ByteChannel>,
        frames: Option<SocketAddr>,
    ) -> colcos_sim::error::Result<Twin> {
        let arena = TwinArena::new(scenario)?;
        let rig = &scenario.spec.rig;
        let n = arena.robot_count();
        let radio = rig.radio_addresses(n)?;
        let rate = scenario.spec.tracker.rate_hz.max(1.0) as f64;
        let mut robots = RobotEnd::new(channel, radio);
        if let Some(manifest) = OnboardManifest::of_scenario(scenario)? {
            let firmware = OnboardFirmware::build(&manifest)?;
            robots.set_onboard(Some(OnboardFleet::new(firmware, n)));
        }
        Ok(Twin {
            arena,
            tracker,
            robots,
            frames: frames.map(FrameClient::connect),
            transform: FrameTransform::new(scenario.arena_size().y as f64),
            tracker_ids: (0..n).map(|i| rig.tracker_id(i)).collect(),
            camera: None,
            fiducials: (f64::NAN, Default::default()),
            last_block: f64::NEG_INFINITY,
            block_period: 1.0 / rate,
        })
    }

    pub fn arena(&self) -> &TwinArena {
        &self.arena
    }
    pub fn arena_mut(&mut self) -> &mut TwinArena {
        &mut self.arena
    }
    /// Sees the arena through `camera` (noise drawn from `seed`); `None`: the tracker reports the
    /// nominal frame change of the true tracked poses, as without calibration.
    pub fn set_camera(&mut self, camera: Option<CameraModel>, seed: u64) {
        self.camera = camera.map(|c| (c, Noise::new(seed)));
    }
    pub fn tracker(&mut self) -> &mut TrackerServer {
        &mut self.tracker
    }
    pub fn robots(&mut self) -> &mut RobotEnd {
        &mut self.robots
    }
    /// The robots' on-board policy, when their firmware carries one (`[rig] onboard`).
    pub fn onboard(&self) -> Option<&OnboardFleet> {
        self.robots.onboard()
    }
    /// Commands received so far.
    pub fn received(&self) -> &[Received] {
        &self.robots.log
    }

    /// One step: commands in, the arena moves, a tracker block out when one is due.
    pub fn tick(&mut self) {
        let latest = self.frames.as_ref().and_then(|f| f.latest());
        if let Some((img, t)) = &latest
            && *t != self.fiducials.0
        {
            let size = self.arena.world().screen().size;
            let seen = detect_fiducials(img, [size[0] as f64, size[1] as f64]);
            self.fiducials.0 = *t;
            self.fiducials.1.push_back((self.arena.time(), seen));
            // A second of history is more than any tracker latency.
            while self.fiducials.1.len() > 2
                && self
                    .fiducials
                    .1
                    .get(1)
                    .is_some_and(|(at, _)| self.arena.time() - at > 1.0)
            {
                self.fiducials.1.pop_front();
            }
        }
        let frame = latest.map(|(img, _)| img);
        self.robots.poll(&mut self.arena, frame.as_deref());
        self.arena.step();
        let now = self.arena.time();
        if now - self.last_block >= self.block_period - 1e-9 {
            self.last_block = now;
            self.publish();
        }
    }

    fn publish(&mut self) {
        // Twin times on this machine's clock, anchored now: a twin that falls behind real time does
        // not drift away from the host's clock.
        let wall_us = SystemTime::now()
            .duration_since(UNIX_EPOCH)
            .map(|d| d.as_micros() as i64)
            .unwrap_or(0);
        let now = self.arena.time();
        let epoch = |t: f32| wall_us - ((now - t as f64) * 1e6).round() as i64;
        let tracked = self.arena.tracked();
        let frame_t = tracked
            .iter()
            .filter(|p| p.seen)
            .map(|p| p.stamp)
            .fold(0.0f32, f32::max);
        let mut poses: Vec<_> = tracked
            .iter()
            .zip(&self.tracker_ids)
            .map(|(p, &id)| {
                let (x, y, yaw) = match &mut self.camera {
                    Some((cam, noise)) => {
                        let q = &p.pose;
                        cam.see_marker(q.pos.x as f64, q.pos.y as f64, q.heading as f64, noise)
                            .unwrap_or((-1.0, -1.0, 0.0))
                    }
                    None => self.transform.to_tracker(&p.pose),
                };
                (id, x, y, yaw, p.seen.then(|| epoch(p.stamp)))
            })
            .collect();
        // Fiducials are seen in the same camera frame as the robots (without a camera model, at
        // the nominal frame change).
        let history = &self.fiducials.1;
        let shown = history
            .iter()
            .rev()
            .find(|(at, _)| *at <= frame_t as f64 + 1e-6)
            .map(|(_, f)| f.as_slice())
            .unwrap_or(&[]);
        for f in shown {
            let seen = match &mut self.camera {
                Some((cam, noise)) => cam.see_fiducial(f[0], f[1], noise),
                None => {
                    let (x, y, _) = self.transform.to_tracker_f64(f[0], f[1], 0.0);
                    Some((x, y))
                }
            };
            if let Some((x, y)) = seen {
                poses.push((-1, x, y, 0.0, Some(epoch(frame_t))));
            }
        }
        self.tracker.publish(epoch(frame_t), &poses);
    }

    /// Runs in real time at the scenario's `dt` until `stop` is set or `duration` s have passed; the
    /// tracker then says `Closed`.
    pub fn run(&mut self, duration: Option<f64>, stop: &AtomicBool) {
        let dt = Duration::from_secs_f64(self.arena.world().dt() as f64);
        let start = Instant::now();
        let mut next = start;
        while !stop.load(Ordering::Relaxed)
            && duration.is_none_or(|d| start.elapsed().as_secs_f64() < d)
        {
            self.tick();
            next += dt;
            let now = Instant::now();
            if next > now {
                std::thread::sleep(next - now);
            } else {
                next = now;
            }
        }
        self.tracker.close();
    }
}
