//! Replays a recorded tracker run: either the SwarmCon server's own log
//! (`Frame <n> Time <t_us> Object <idx> <ID> <x> <y> <yaw_rad>`, one line per object, grouped by
//! frame) or a capture of the TCP stream's blocks; at recorded speed, a multiple of it, or as fast as
//! the consumer polls.

use super::shared::{Shared, ThreadedSource};
use super::{ConnectionState, SourceError, frame_to_poses};
use crate::protocol::swarmcon::{
    FrameTransform, SlotPose, SlotState, StreamParser, TrackerFrame, TrackerMessage,
};
use std::path::Path;
use std::time::{Duration, Instant};

/// Files larger than this are refused rather than read into memory.
const MAX_FILE: u64 = 512 * 1024 * 1024;

/// Reads a replay file in either format.
pub(crate) fn load_replay(path: &Path) -> Result<Vec<TrackerFrame>, SourceError> {
    let err = |reason: String| SourceError::Replay {
        path: path.display().to_string(),
        reason,
    };
    let len = std::fs::metadata(path)
        .map_err(|e| err(e.to_string()))?
        .len();
    if len > MAX_FILE {
        return Err(err(format!(
            "{len} bytes is more than the {MAX_FILE} a replay may hold"
        )));
    }
    let bytes = std::fs::read(path).map_err(|e| err(e.to_string()))?;
    let first = bytes
        .split(|&b| b == b'\n')
        .map(|l| l.trim_ascii())
        .find(|l| !l.is_empty())
        .ok_or_else(|| err("file is empty".into()))?;
    let frames = if first.starts_with(b"Frame ") {
        let text = std::str::from_utf8(&bytes).map_err(|_| err("not UTF-8 text".into()))?;
        parse_server_log(text).map_err(err)?
    } else {
        let mut p = StreamParser::new();
        p.feed(&bytes)
            .into_iter()
            .filter_map(|m| match m {
                TrackerMessage::Frame(f) => Some(f),
                TrackerMessage::Event(_) => None,
            })
            .collect()
    };
    if frames.is_empty() {
        return Err(err("no tracker frames in it".into()));
    }
    Ok(frames)
}

/// Parses the server's log into frames; an error names the line.
pub(crate) fn parse_server_log(text: &str) -> Result<Vec<TrackerFrame>, String> {
    let mut frames: Vec<TrackerFrame> = Vec::new();
    let mut current: Option<i64> = None;
    for (i, line) in text.lines().enumerate() {
        let tok: Vec<&str> = line.split_ascii_whitespace().collect();
        if tok.is_empty() {
            continue;
        }
        let bad = |what: &str| {
            format!(
                "line {}: {what}: {:?}",
                i + 1,
                line.chars().take(80).collect::<String>()
            )
        };
        if tok.len() != 10 || tok[0] != "Frame" || tok[2] != "Time" || tok[4] != "Object" {
            return Err(bad(
                "expected `Frame <n> Time <t> Object <idx> <ID> <x> <y> <yaw>`",
            ));
        }
        let n: i64 = tok[1].parse().map_err(|_| bad("frame number"))?;
        let t_us: i64 = tok[3].parse().map_err(|_| bad("time"))?;
        let id: i32 = tok[6].parse().map_err(|_| bad("ID"))?;
        let num = |s: &str, what| {
            s.parse::<f64>()
                .ok()
                .filter(|v| v.is_finite() && v.abs() < 1e4)
                .ok_or_else(|| bad(what))
        };
        let (x, y, yaw_rad) = (num(tok[7], "x")?, num(tok[8], "y")?, num(tok[9], "yaw")?);
        if current != Some(n) {
            current = Some(n);
            frames.push(TrackerFrame {
                t_us,
                found: 0,
                tracked: 0,
                updated: None,
                robots: Vec::new(),
            });
        }
        if let Some(f) = frames.last_mut() {
            f.found += 1;
            f.tracked += 1;
            f.robots.push(SlotPose {
                id,
                x,
                y,
                yaw_deg: yaw_rad.to_degrees(),
                last_seen_us: t_us,
                state: SlotState::Fresh,
            });
        }
    }
    Ok(frames)
}

pub(super) fn spawn(
    frames: Vec<TrackerFrame>,
    speed: Option<f64>,
    transform: FrameTransform,
) -> ThreadedSource {
    ThreadedSource::spawn(Shared::new(), false, move |shared| {
        shared.set_state(ConnectionState::Connected);
        let start = Instant::now();
        let t0 = frames.first().map_or(0, |f| f.t_us);
        for f in &frames {
            if let Some(speed) = speed {
                let due = Duration::from_secs_f64(((f.t_us - t0).max(0) as f64 * 1e-6) / speed);
                if !shared.sleep(due.saturating_sub(start.elapsed())) {
                    return;
                }
            } else if shared.stopped() {
                return;
            }
            shared.publish(f.t_us as f64 * 1e-6, frame_to_poses(f, &transform));
        }
        shared.set_state(ConnectionState::Finished);
    })
}
