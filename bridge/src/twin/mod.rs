//! The digital twin: the simulator playing the rig over the rig's real wire formats. A SwarmCon
//! position server on TCP writes the tracker model's poses (noise, latency, dropouts, stale slots) in
//! the exact text format; the robots' end of the serial protocol (a pseudo-terminal or UDP) applies
//! the commands it receives to the simulated robots and answers data requests with telemetry whose
//! colour counts come from the frames the bridge displays. Faults on demand.
mod plant;
mod robot_end;
mod tracker_server;

pub use plant::{FIRMWARE_TIMEOUT, TwinPlant};
pub use robot_end::{
    BUMPER_DARK, BUMPER_SPAN, ByteChannel, PtyChannel, Received, RobotEnd, RobotFaults, UdpChannel,
    bumper_reading,
};
pub use tracker_server::{TrackerFaults, TrackerServer};

use crate::frames::FrameClient;
use crate::swarmcon::FrameTransform;
use colcos_sim::scenario::Scenario;
use std::net::SocketAddr;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

pub struct Twin {
    plant: TwinPlant,
    tracker: TrackerServer,
    robots: RobotEnd,
    frames: Option<FrameClient>,
    transform: FrameTransform,
    tracker_ids: Vec<i32>,
    /// Epoch µs at twin time 0.
    epoch0_us: i64,
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
        let plant = TwinPlant::new(scenario)?;
        let rig = &scenario.spec.rig;
        let n = plant.robot_count();
        let radio = rig.radio_addresses(n)?;
        let rate = scenario.spec.tracker.rate_hz.max(1.0) as f64;
        Ok(Twin {
            plant,
            tracker,
            robots: RobotEnd::new(channel, radio),
            frames: frames.map(FrameClient::connect),
            transform: FrameTransform::new(scenario.arena_size().y as f64),
            tracker_ids: (0..n).map(|i| rig.tracker_id(i)).collect(),
            epoch0_us: SystemTime::now()
                .duration_since(UNIX_EPOCH)
                .map(|d| d.as_micros() as i64)
                .unwrap_or(0),
            last_block: f64::NEG_INFINITY,
            block_period: 1.0 / rate,
        })
    }

    pub fn plant(&self) -> &TwinPlant {
        &self.plant
    }
    pub fn tracker(&mut self) -> &mut TrackerServer {
        &mut self.tracker
    }
    pub fn robots(&mut self) -> &mut RobotEnd {
        &mut self.robots
    }
    /// Commands received so far.
    pub fn received(&self) -> &[Received] {
        &self.robots.log
    }

    /// One step: commands in, the arena moves, a tracker block out when one is due.
    pub fn tick(&mut self) {
        let frame = self
            .frames
            .as_ref()
            .and_then(|f| f.latest())
            .map(|(img, _)| img);
        self.robots.poll(&mut self.plant, frame.as_deref());
        self.plant.step();
        let now = self.plant.time();
        if now - self.last_block >= self.block_period - 1e-9 {
            self.last_block = now;
            self.publish();
        }
    }

    fn publish(&mut self) {
        let epoch = |t: f32| self.epoch0_us + (t as f64 * 1e6).round() as i64;
        let tracked = self.plant.tracked();
        let frame_t = tracked
            .iter()
            .filter(|p| p.seen)
            .map(|p| p.stamp)
            .fold(0.0f32, f32::max);
        let poses: Vec<_> = tracked
            .iter()
            .zip(&self.tracker_ids)
            .map(|(p, &id)| {
                let (x, y, yaw) = self.transform.to_tracker(&p.pose);
                (id, x, y, yaw, p.seen.then(|| epoch(p.stamp)))
            })
            .collect();
        self.tracker.publish(epoch(frame_t), &poses);
    }

    /// Runs in real time at the scenario's `dt` until `stop` is set or `duration` s have passed; the
    /// tracker then says `Closed`.
    pub fn run(&mut self, duration: Option<f64>, stop: &AtomicBool) {
        let dt = Duration::from_secs_f64(self.plant.world().dt() as f64);
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
