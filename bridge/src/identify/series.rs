//! A rig log as each robot's two time series: the wheel commands the bridge sent (decoded from the
//! command frames on the wire) and the poses the tracker delivered, stamped with their capture time
//! (the tick's time less the pose's age), so that the tracker's latency is not mistaken for the
//! robot's; and the colour counts each robot reported, stamped with the time it was asked for them.
use crate::protocol::colias::{CommandDecoder, CommandPacket, HostCommand, colour_to_sim};
use crate::rig::replay::RecordedTick;
use colcos_sim::scenario::{BROADCAST_ID, Scenario};

/// One robot's commands and poses.
#[derive(Clone, Debug, Default)]
pub struct RobotSeries {
    /// Time each command was sent, s since the run's start, and (left, right) m/s: the robot drives
    /// it until the next.
    pub commands: Vec<(f64, [f64; 2])>,
    /// Capture time, s since the run's start, and (x m, y m, heading rad): fresh detections only.
    pub poses: Vec<(f64, [f64; 3])>,
    /// Telemetry colour counts in the simulator's sensor order, stamped with the time the bridge
    /// asked for them (a robot reads as it hears the request; the answer's arrival is later by the
    /// link's round trip), or with the arrival where no request was logged.
    pub telemetry: Vec<(f64, [[u16; 3]; 4])>,
    /// Time of every answer to a data request: (request sent, robot clock s, answer received).
    pub answers: Vec<(f64, f64, f64)>,
}

/// Why a log cannot be fitted.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum SeriesError {
    #[error(
        "the rig log holds no ticks (not a log of `colcos bridge`, or cut before its first tick)"
    )]
    NoTicks,
    #[error(
        "the rig log holds no wheel commands: nothing drove the robots (record one with `colcos rig excite`)"
    )]
    NoCommands,
    #[error("the rig log holds no poses from the tracker")]
    NoPoses,
    #[error(
        "the rig log is of scenario {log:?} with {log_robots} robots, not {scenario:?} with {robots}"
    )]
    OtherScenario {
        log: String,
        log_robots: String,
        scenario: String,
        robots: usize,
    },
}

/// Checks the log's metadata (`rig`: scenario name and robot count) against `scenario`.
pub fn check_scenario(
    metadata: &[(String, std::collections::BTreeMap<String, String>)],
    scenario: &Scenario,
) -> Result<(), SeriesError> {
    let Some((_, rig)) = metadata.iter().find(|(name, _)| name == "rig") else {
        return Ok(());
    };
    let name = rig.get("scenario").cloned().unwrap_or_default();
    let robots = rig.get("robots").cloned().unwrap_or_default();
    if name != scenario.spec.name || robots != scenario.robot_count().to_string() {
        return Err(SeriesError::OtherScenario {
            log: name,
            log_robots: robots,
            scenario: scenario.spec.name.clone(),
            robots: scenario.robot_count(),
        });
    }
    Ok(())
}

/// Every robot's series from the log's ticks, for `scenario` (its radio addresses and tracker IDs).
pub fn robot_series(
    ticks: &[RecordedTick],
    scenario: &Scenario,
) -> Result<Vec<RobotSeries>, SeriesError> {
    if ticks.is_empty() {
        return Err(SeriesError::NoTicks);
    }
    let n = scenario.robot_count();
    let rig = &scenario.spec.rig;
    let radio = rig.radio_addresses(n).unwrap_or_default();
    let tracker: Vec<i64> = (0..n).map(|i| rig.tracker_id(i) as i64).collect();
    let mut out = vec![RobotSeries::default(); n];
    let mut decoder = CommandDecoder::new();
    let (mut any_command, mut any_pose) = (false, false);
    // Per robot, when it was last asked for data (in an earlier tick: an answer comes a tick later
    // at the earliest, as the loop reads telemetry before it sends).
    let mut asked: Vec<Option<f64>> = vec![None; n];
    for tick in ticks {
        for tm in &tick.telemetry {
            if let Some(i) = radio.iter().position(|r| *r == tm.id) {
                let read = asked[i].unwrap_or(tick.t);
                out[i].telemetry.push((read, colour_to_sim(tm.colour)));
                if let Some(sent) = asked[i] {
                    out[i]
                        .answers
                        .push((sent, tm.sys_t_ms as f64 * 1e-3, tick.t));
                }
            }
        }
        for frame in &tick.commands {
            for payload in decoder.feed(frame) {
                let Ok(packet) = CommandPacket::decode(&payload) else {
                    continue;
                };
                if let HostCommand::RequestTelemetry(_) = packet.command
                    && let Some(i) = radio.iter().position(|r| *r == packet.id)
                {
                    asked[i] = Some(tick.t);
                }
                let Some(wheels) = wheels_of(&packet.command) else {
                    continue;
                };
                any_command = true;
                for (i, s) in out.iter_mut().enumerate() {
                    if packet.id == BROADCAST_ID || radio.get(i) == Some(&packet.id) {
                        s.commands.push((tick.t, wheels));
                    }
                }
            }
        }
        for p in tick.poses.iter().filter(|p| p.fresh) {
            if let Some(i) = tracker.iter().position(|id| *id == p.id as i64) {
                any_pose = true;
                let pose = [
                    p.pose.pos.x as f64,
                    p.pose.pos.y as f64,
                    p.pose.heading as f64,
                ];
                let t = tick.t - p.age;
                // The tracker repeats a block until the next: one sample per capture.
                if out[i].poses.last().is_none_or(|(last, _)| t > *last + 1e-4) {
                    out[i].poses.push((t, pose));
                }
            }
        }
    }
    if !any_command {
        return Err(SeriesError::NoCommands);
    }
    if !any_pose {
        return Err(SeriesError::NoPoses);
    }
    Ok(out)
}

/// The wheel speeds a command frame asks for; `None` for frames that are not motion.
fn wheels_of(cmd: &HostCommand) -> Option<[f64; 2]> {
    match *cmd {
        HostCommand::WheelSpeeds { left, right } => Some([left as f64, right as f64]),
        HostCommand::Motion { kind, speed } => {
            let w = crate::twin::legacy_motion_wheels(kind, speed);
            Some([w.left as f64, w.right as f64])
        }
        _ => None,
    }
}
