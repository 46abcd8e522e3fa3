//! Safety stops: the frames that stop one robot or all of them, sent ahead of anything queued, and the
//! guard that sends them whichever way the loop ends (a panic included).
use super::recorder::{Recorder, Topic};
use super::watchdog::StopReason;
use crate::protocol::colias::{BROADCAST_ID, CommandPacket, HostCommand, LegacyDrive, MotionKind};
use crate::transport::RobotLink;
use crate::transport::epoch_ns;
use colcos_sim::behaviour::WheelCommand;
use colcos_sim::scenario::Firmware;
use std::collections::HashMap;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// At most one warning per kind of stop in this long; the others are counted into the next.
const WARN_EVERY: Duration = Duration::from_secs(5);

/// When each kind of stop was last warned of, and how many went unsaid since.
#[derive(Default)]
pub(crate) struct WarnLimiter(Mutex<HashMap<&'static str, (Instant, u64)>>);

impl WarnLimiter {
    /// Whether to warn of a stop of `kind` now, and how many of that kind went unsaid before it.
    fn admit(&self, kind: &'static str) -> Option<u64> {
        let mut m = self.0.lock().unwrap_or_else(|e| e.into_inner());
        let now = Instant::now();
        match m.get_mut(kind) {
            Some((last, unsaid)) if now.duration_since(*last) < WARN_EVERY => {
                *unsaid += 1;
                None
            }
            Some((last, unsaid)) => {
                let n = *unsaid;
                (*last, *unsaid) = (now, 0);
                Some(n)
            }
            None => {
                m.insert(kind, (now, 0));
                Some(0)
            }
        }
    }
}

pub(crate) type SharedLink = Arc<Mutex<Box<dyn RobotLink>>>;
pub(crate) type SharedLog = Arc<Mutex<Option<Recorder>>>;

pub(crate) fn record(log: &SharedLog, topic: Topic, data: &[u8]) {
    if let Ok(mut l) = log.lock()
        && let Some(r) = l.as_mut()
    {
        let _ = r.record(topic, epoch_ns(), data);
    }
}

/// The host's millisecond stamp of a frame sent `t` s after the loop started (wrapping at 2^32).
pub(crate) fn t_ms(t: f64) -> u32 {
    (t.max(0.0) * 1e3) as u64 as u32
}

/// The command that drives robot `id` with `cmd` on firmware `firmware`.
pub(crate) fn drive_packet(
    id: u8,
    t: u32,
    cmd: WheelCommand,
    firmware: Firmware,
    legacy: &LegacyDrive,
) -> CommandPacket {
    let command = match firmware {
        Firmware::Wheels => HostCommand::WheelSpeeds {
            left: cmd.left,
            right: cmd.right,
        },
        Firmware::Motion => legacy.map(cmd),
    };
    CommandPacket::new(id, t, command)
}

/// The command that stops robot `id` (or all of them, [`BROADCAST_ID`]) at once.
pub(crate) fn stop_packet(id: u8, t: u32, firmware: Firmware) -> CommandPacket {
    let command = match firmware {
        Firmware::Wheels => HostCommand::WheelSpeeds {
            left: 0.0,
            right: 0.0,
        },
        Firmware::Motion => HostCommand::Motion {
            kind: MotionKind::Stop,
            speed: 0.0,
        },
    };
    CommandPacket::new(id, t, command)
}

/// What the watchdog and the exit guard need to stop robots.
#[derive(Clone)]
pub(crate) struct Stopper {
    pub link: SharedLink,
    pub log: SharedLog,
    pub radio: Vec<u8>,
    pub firmware: Firmware,
    pub start: Instant,
    pub warned: Arc<WarnLimiter>,
}

impl Stopper {
    /// Sends the stop `reason` calls for, ahead of anything queued, and logs it (on its own topic:
    /// stops come from the watchdog's clock, not from the loop's inputs, so a replay leaves them out).
    pub(crate) fn stop(&self, reason: &StopReason) {
        let id = match reason.robot() {
            None => BROADCAST_ID,
            Some(i) => self.radio.get(i).copied().unwrap_or(BROADCAST_ID),
        };
        let packet = stop_packet(id, t_ms(self.start.elapsed().as_secs_f64()), self.firmware);
        let sent = match self.link.lock() {
            Ok(mut link) => link.stop_now(packet).map_err(|e| e.to_string()),
            Err(_) => Err("link lock poisoned".to_string()),
        };
        if sent.is_ok() {
            record(&self.log, Topic::Stops, &packet.to_frame());
        }
        let event = serde_json::json!({
            "kind": reason.kind(),
            "robot": reason.robot(),
            "detail": reason.to_string(),
            "sent": sent.is_ok(),
        });
        record(&self.log, Topic::Events, event.to_string().as_bytes());
        let whom = if id == BROADCAST_ID {
            "all robots".to_string()
        } else {
            format!("radio {id}")
        };
        // A normal end stops the robots as a matter of course: said, not warned of.
        if let StopReason::Shutdown(why) = reason {
            log::debug!("stopped {whom}: {why}");
            return;
        }
        let Some(unsaid) = self.warned.admit(reason.kind()) else {
            return;
        };
        let more = if unsaid > 0 {
            format!(
                " ({unsaid} more of this kind in the last {} s)",
                WARN_EVERY.as_secs()
            )
        } else {
            String::new()
        };
        let failed = match &sent {
            Ok(()) => String::new(),
            Err(e) => format!("; the stop could not be sent: {e}"),
        };
        log::warn!("safety stop of {whom}: {reason}{more}{failed}");
    }
}

/// Stops every robot when dropped: the loop's last word, also when it unwinds from a panic.
pub(crate) struct StopOnDrop(pub Stopper);

impl Drop for StopOnDrop {
    fn drop(&mut self) {
        self.0
            .stop(&StopReason::Shutdown("the live loop ended".into()));
        if let Ok(mut l) = self.0.log.lock()
            && let Some(r) = l.take()
        {
            let _ = r.finish();
        }
    }
}
