//! Shares a slow serial channel between robots: at most what the line can carry is sent, only the
//! newest command per robot waits (a newer one replaces it), and robots take turns. Parameter writes
//! are the exception: each carries its own values, so they wait in order, ahead of the robot's
//! newest command (a policy is started only after its parameters are in). A telemetry request waits
//! in a slot of its own, ahead of the robot's drive command: on a saturated line a drive command
//! replacing it would leave the robot unasked, and then reported silent.

use crate::protocol::colias::{
    COMMAND_FRAME_LEN, CommandPacket, HostCommand, TELEMETRY_FRAME_LEN, airtime_s,
};
use std::collections::VecDeque;
use std::time::{Duration, Instant};

/// Parameter writes one robot may have waiting; more are dropped (and counted).
const MAX_WRITES_WAITING: usize = 64;

/// Running totals of a scheduler.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SchedulerCounters {
    pub submitted: u64,
    pub sent: u64,
    /// Commands replaced by a newer one for the same robot before they could be sent.
    pub superseded: u64,
    /// Parameter writes dropped because too many were waiting for their robot.
    pub dropped_writes: u64,
}

/// Airtime-limited, newest-wins command queue (one slot per robot id, so never more than 256).
#[derive(Debug)]
pub struct AirtimeScheduler {
    slots: Box<[Option<CommandPacket>; 256]>,
    /// Per robot id, the newest telemetry request.
    requests: Box<[Option<CommandPacket>; 256]>,
    /// Per robot id, parameter writes in order.
    writes: Vec<VecDeque<CommandPacket>>,
    pending: usize,
    /// The id after the last one sent: where the round-robin scan starts.
    cursor: usize,
    command_airtime: Duration,
    telemetry_airtime: Duration,
    /// Idle time that may be spent at once afterwards: a tick's worth lets a burst go out per tick.
    burst: Duration,
    free_at: Option<Instant>,
    counters: SchedulerCounters,
}

impl AirtimeScheduler {
    /// A scheduler for a line at `baud`, 8N1.
    pub fn new(baud: u32) -> Self {
        AirtimeScheduler {
            slots: Box::new([None; 256]),
            requests: Box::new([None; 256]),
            writes: vec![VecDeque::new(); 256],
            pending: 0,
            cursor: 0,
            command_airtime: Duration::from_secs_f64(airtime_s(COMMAND_FRAME_LEN, baud)),
            telemetry_airtime: Duration::from_secs_f64(airtime_s(TELEMETRY_FRAME_LEN, baud)),
            burst: Duration::from_millis(20),
            free_at: None,
            counters: SchedulerCounters::default(),
        }
    }

    /// Sets how much idle airtime may be used in one go.
    pub fn with_burst(mut self, burst: Duration) -> Self {
        self.burst = burst;
        self
    }

    pub fn command_airtime(&self) -> Duration {
        self.command_airtime
    }

    pub fn pending(&self) -> usize {
        self.pending
    }

    pub fn counters(&self) -> SchedulerCounters {
        self.counters
    }

    /// Drops every queued command (a safety stop goes out ahead of them, and none may follow it).
    pub fn clear(&mut self) {
        for slot in self.slots.iter_mut().chain(self.requests.iter_mut()) {
            *slot = None;
        }
        self.writes.iter_mut().for_each(VecDeque::clear);
        self.pending = 0;
    }

    /// Queues a command, replacing any unsent one for the same robot.
    pub fn submit(&mut self, p: CommandPacket) {
        self.counters.submitted += 1;
        if matches!(
            p.command,
            HostCommand::WriteParamsAt { .. } | HostCommand::WriteParams(_)
        ) {
            let queue = &mut self.writes[p.id as usize];
            if queue.len() >= MAX_WRITES_WAITING {
                self.counters.dropped_writes += 1;
                return;
            }
            queue.push_back(p);
            self.pending += 1;
            return;
        }
        let slots = match p.command {
            HostCommand::RequestTelemetry(_) => &mut self.requests,
            _ => &mut self.slots,
        };
        if slots[p.id as usize].replace(p).is_some() {
            self.counters.superseded += 1;
        } else {
            self.pending += 1;
        }
    }

    /// The airtime a command occupies, including the telemetry replies it asks for.
    fn cost(&self, p: &CommandPacket) -> Duration {
        match p.command {
            HostCommand::RequestTelemetry(n) => {
                self.command_airtime + self.telemetry_airtime * n as u32
            }
            _ => self.command_airtime,
        }
    }

    /// The next command to send now, if the channel has room for it.
    pub fn next_due(&mut self, now: Instant) -> Option<CommandPacket> {
        if self.pending == 0 {
            return None;
        }
        let earliest = now.checked_sub(self.burst).unwrap_or(now);
        let free_at = self.free_at.map_or(earliest, |f| f.max(earliest));
        if free_at > now {
            return None;
        }
        let id = (0..256).map(|k| (self.cursor + k) % 256).find(|&i| {
            self.slots[i].is_some() || self.requests[i].is_some() || !self.writes[i].is_empty()
        })?;
        let p = match self.writes[id].pop_front() {
            Some(w) => w,
            None => self.requests[id].take().or_else(|| self.slots[id].take())?,
        };
        self.pending -= 1;
        self.cursor = (id + 1) % 256;
        self.free_at = Some(free_at + self.cost(&p));
        self.counters.sent += 1;
        Some(p)
    }

    /// Everything that may be sent now.
    pub fn drain_due(&mut self, now: Instant) -> Vec<CommandPacket> {
        std::iter::from_fn(|| self.next_due(now)).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::protocol::colias::MotionKind;

    fn cmd(id: u8, speed: f32) -> CommandPacket {
        CommandPacket::new(
            id,
            0,
            HostCommand::Motion {
                kind: MotionKind::Forward,
                speed,
            },
        )
    }

    #[test]
    fn newest_wins_and_rate_is_bounded() {
        let mut s = AirtimeScheduler::new(115_200);
        let t0 = Instant::now();
        for round in 0..10 {
            for id in 0..20 {
                s.submit(cmd(id, round as f32));
            }
        }
        assert_eq!(s.pending(), 20);
        assert_eq!(s.counters().superseded, 180);
        let first = s.drain_due(t0);
        // 20 ms of credit at 3.125 ms a frame.
        assert_eq!(first.len(), 7);
        assert!(first.iter().all(|p| p.command == cmd(0, 9.0).command));
        // Later ticks send the rest, at most a burst at a time.
        let mut rest = Vec::new();
        for tick in 1..5 {
            let now = t0 + Duration::from_millis(20 * tick);
            let due = s.drain_due(now);
            assert!(due.len() <= 7);
            rest.extend(due);
        }
        assert_eq!(rest.len(), 13);
        let mut ids: Vec<u8> = first.iter().chain(&rest).map(|p| p.id).collect();
        ids.sort_unstable();
        assert_eq!(ids, (0..20).collect::<Vec<_>>());
    }

    #[test]
    fn steady_rate_matches_airtime() {
        let mut s = AirtimeScheduler::new(115_200);
        let t0 = Instant::now();
        let mut sent = 0;
        for tick in 0..50 {
            for id in 0..30 {
                s.submit(cmd(id, 0.1));
            }
            sent += s.drain_due(t0 + Duration::from_millis(20 * tick)).len();
        }
        // One second of line at 3.125 ms a frame is 320 frames, plus the initial burst.
        assert!((310..=330).contains(&sent), "{sent}");
    }

    #[test]
    fn parameter_writes_wait_in_order_ahead_of_the_newest_command() {
        let mut s = AirtimeScheduler::new(115_200).with_burst(Duration::from_secs(1));
        let write = |id: u8, offset: u16| {
            CommandPacket::new(
                id,
                0,
                HostCommand::WriteParamsAt {
                    offset,
                    count: 5,
                    values: [offset as f32; 5],
                },
            )
        };
        s.submit(cmd(1, 0.1));
        for k in 0..12 {
            s.submit(write(1, 5 * k));
        }
        s.submit(CommandPacket::new(1, 0, HostCommand::RunPolicy { hash: 9 }));
        s.submit(write(2, 0));
        let sent = s.drain_due(Instant::now());
        assert_eq!(s.counters().superseded, 1);
        let to_one: Vec<_> = sent
            .iter()
            .filter(|p| p.id == 1)
            .map(|p| p.command)
            .collect();
        assert_eq!(to_one.len(), 13);
        for (k, c) in to_one[..12].iter().enumerate() {
            assert_eq!(*c, write(1, 5 * k as u16).command);
        }
        assert_eq!(to_one[12], HostCommand::RunPolicy { hash: 9 });
        assert!(sent.iter().any(|p| p.id == 2));
        // A runaway sender cannot grow the queue without bound.
        for _ in 0..100 {
            s.submit(write(3, 0));
        }
        assert_eq!(s.counters().dropped_writes, 100 - MAX_WRITES_WAITING as u64);
        s.clear();
        assert_eq!(s.pending(), 0);
    }

    #[test]
    fn telemetry_requests_reserve_reply_airtime() {
        let mut s = AirtimeScheduler::new(115_200).with_burst(Duration::ZERO);
        let t0 = Instant::now();
        s.submit(CommandPacket::new(1, 0, HostCommand::RequestTelemetry(2)));
        s.submit(cmd(2, 0.0));
        assert_eq!(s.drain_due(t0).len(), 1);
        assert!(s.next_due(t0 + Duration::from_millis(20)).is_none());
        assert!(s.next_due(t0 + Duration::from_millis(21)).is_some());
    }

    /// On a line that cannot carry every robot's drive command each tick, a telemetry request is
    /// neither replaced by the robot's next drive command nor replaces it: both go out.
    #[test]
    fn a_telemetry_request_survives_a_saturated_line() {
        let mut s = AirtimeScheduler::new(115_200);
        let t0 = Instant::now();
        let request = CommandPacket::new(15, 0, HostCommand::RequestTelemetry(1));
        let mut sent = Vec::new();
        for tick in 0..10u64 {
            for id in 0..20 {
                s.submit(cmd(id, tick as f32));
            }
            if tick == 0 {
                s.submit(request);
            }
            sent.extend(s.drain_due(t0 + Duration::from_millis(20 * tick)));
        }
        assert!(s.counters().superseded > 50, "{:?}", s.counters());
        let to_15: Vec<_> = sent.iter().filter(|p| p.id == 15).collect();
        assert_eq!(to_15.iter().filter(|p| **p == &request).count(), 1);
        assert!(
            to_15
                .iter()
                .any(|p| matches!(p.command, HostCommand::Motion { .. }))
        );
    }
}
