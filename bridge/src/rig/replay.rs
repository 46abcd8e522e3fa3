//! A recorded rig run put through the loop again: each tick's poses, telemetry, time and watchdog
//! stops from the rig log go into a fresh [`LoopCore`], and the command frames it sends come out; the
//! same inputs give the same bytes, so a replay checks that a run is reproducible, and replays with a
//! policy (the Python `plant="replay"`) see exactly what the rig saw.
use super::core::{LoopCore, PoseIn, TickInput};
use super::recorder::{Recorded, Topic, read_log};
use crate::protocol::colias::{Telemetry, TelemetryDecoder};
use colcos_sim::robot::Pose;
use serde::Deserialize;

/// One tick of a recorded run: what went in and the frames that came out.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RecordedTick {
    pub tick: u64,
    pub t: f64,
    pub step: f64,
    pub poses: Vec<PoseIn>,
    pub telemetry: Vec<Telemetry>,
    /// Robots the watchdog held stopped.
    pub stopped: Vec<bool>,
    /// The command frames the tick sent, as on the wire.
    pub commands: Vec<Vec<u8>>,
}

#[derive(Debug, thiserror::Error)]
pub enum ReplayError {
    #[error("rig log: {0}")]
    Read(String),
    #[error("rig log, message {index} on {topic}: {reason}")]
    Message {
        index: usize,
        topic: &'static str,
        reason: String,
    },
    #[error(
        "rig log: no tick records (/ticks): it was written by an older colcos or the run ended before its first tick"
    )]
    NoTicks,
}

#[derive(Deserialize)]
struct PoseJson {
    id: u32,
    x: f32,
    y: f32,
    heading: f32,
    age: f64,
    fresh: bool,
}

#[derive(Deserialize)]
struct TickJson {
    tick: u64,
    t: f64,
    step: f64,
    stopped: Vec<usize>,
    commands: usize,
}

/// The ticks of the rig log `bytes` for a scenario of `robots` robots, in order. A log cut short by a
/// killed run gives the ticks before the cut.
pub fn read_ticks(bytes: &[u8], robots: usize) -> Result<Vec<RecordedTick>, ReplayError> {
    ticks_of(&read_log(bytes), robots)
}

/// [`read_ticks`] over messages already read.
pub fn ticks_of(log: &[Recorded], robots: usize) -> Result<Vec<RecordedTick>, ReplayError> {
    let mut out = Vec::new();
    let mut cur = RecordedTick::default();
    let mut decoder = TelemetryDecoder::new();
    let bad = |index: usize, topic: Topic, reason: String| ReplayError::Message {
        index,
        topic: topic.name(),
        reason,
    };
    for (index, m) in log.iter().enumerate() {
        match m.topic {
            Topic::Poses => {
                let poses: Vec<PoseJson> = serde_json::from_slice(&m.data)
                    .map_err(|e| bad(index, m.topic, e.to_string()))?;
                cur.poses = poses
                    .into_iter()
                    .map(|p| PoseIn {
                        id: p.id,
                        pose: Pose {
                            pos: glam::Vec2::new(p.x, p.y),
                            heading: p.heading,
                        },
                        age: p.age,
                        fresh: p.fresh,
                    })
                    .collect();
            }
            Topic::Telemetry => {
                for payload in decoder.feed(&m.data) {
                    cur.telemetry.push(Telemetry::decode(&payload));
                }
            }
            Topic::Commands => cur.commands.push(m.data.clone()),
            Topic::Ticks => {
                let t: TickJson = serde_json::from_slice(&m.data)
                    .map_err(|e| bad(index, m.topic, e.to_string()))?;
                if t.commands != cur.commands.len() {
                    return Err(bad(
                        index,
                        m.topic,
                        format!(
                            "tick {} says {} command frames, the log holds {} before it",
                            t.tick,
                            t.commands,
                            cur.commands.len()
                        ),
                    ));
                }
                let mut stopped = vec![false; robots];
                for i in t.stopped {
                    if let Some(s) = stopped.get_mut(i) {
                        *s = true;
                    }
                }
                out.push(RecordedTick {
                    tick: t.tick,
                    t: t.t,
                    step: t.step,
                    stopped,
                    ..std::mem::take(&mut cur)
                });
            }
            Topic::Frames | Topic::Events | Topic::Stops => {}
        }
    }
    if out.is_empty() {
        return Err(ReplayError::NoTicks);
    }
    Ok(out)
}

/// How a replay compared with the recording.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct ReplayReport {
    pub ticks: u64,
    /// Command frames recorded and replayed.
    pub frames: u64,
    /// Ticks whose frames differ from the recording.
    pub mismatched_ticks: u64,
    /// The first tick that differs, if any.
    pub first_mismatch: Option<u64>,
}

/// Feeds one recorded tick's inputs to `core` (with a policy's `overrides`, empty for none).
pub fn feed(
    core: &mut LoopCore,
    tick: &RecordedTick,
    overrides: &[Option<colcos_sim::behaviour::WheelCommand>],
) {
    core.tick(&TickInput {
        t: tick.t,
        step: tick.step,
        poses: &tick.poses,
        telemetry: &tick.telemetry,
        stopped: &tick.stopped,
        overrides,
    });
}

/// Runs every tick of `ticks` through `core` with the behaviours deciding and compares the frames it
/// sends with the recorded ones, byte for byte.
pub fn replay(core: &mut LoopCore, ticks: &[RecordedTick]) -> ReplayReport {
    let mut report = ReplayReport::default();
    for tick in ticks {
        feed(core, tick, &[]);
        report.ticks += 1;
        report.frames += tick.commands.len() as u64;
        let same = core.packets().len() == tick.commands.len()
            && core
                .packets()
                .iter()
                .zip(&tick.commands)
                .all(|(p, rec)| p.to_frame() == *rec);
        if !same {
            report.mismatched_ticks += 1;
            report.first_mismatch.get_or_insert(tick.tick);
        }
    }
    report
}
