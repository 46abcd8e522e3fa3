//! Reassembles tracker frames from an arbitrary byte stream: blocks may be split across reads and
//! several blocks may arrive in one read. Bad lines are counted, never fatal.

use super::line::{LineBuffer, LineChunk};
use super::parse::{TrackerError, TrackerLine, parse_line};
use super::{SlotPose, TrackerEvent, TrackerFrame};

/// What the parser emits, in stream order.
#[derive(Clone, Debug, PartialEq)]
pub enum TrackerMessage {
    Frame(TrackerFrame),
    Event(TrackerEvent),
}

/// Running totals since the parser was created.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ParserCounters {
    pub bytes: u64,
    pub lines: u64,
    pub frames: u64,
    pub events: u64,
    /// Lines that could not be parsed or did not fit the block structure.
    pub errors: u64,
    /// Blocks announced by a header but not emitted (cut short or holding a bad line).
    pub dropped_frames: u64,
}

#[derive(Debug)]
struct Pending {
    frame: TrackerFrame,
    expected: usize,
    /// A line of this block was bad: finish consuming it, then drop it.
    poisoned: bool,
}

#[derive(Debug, Default)]
struct Assembler {
    pending: Option<Pending>,
    counters: ParserCounters,
    last_error: Option<TrackerError>,
}

impl Assembler {
    fn error(&mut self, e: TrackerError) {
        self.counters.errors += 1;
        self.last_error = Some(e);
    }

    /// A block that ends before all its `Robot` lines arrived.
    fn cut_short(&mut self) {
        if let Some(p) = self.pending.take() {
            self.counters.dropped_frames += 1;
            self.error(TrackerError::Truncated {
                got: p.frame.robots.len(),
                expected: p.expected,
            });
        }
    }

    fn finish(&mut self, p: Pending, out: &mut Vec<TrackerMessage>) {
        if p.poisoned {
            self.counters.dropped_frames += 1;
        } else {
            self.counters.frames += 1;
            out.push(TrackerMessage::Frame(p.frame));
        }
    }

    fn event(&mut self, e: TrackerEvent, out: &mut Vec<TrackerMessage>) {
        self.cut_short();
        self.counters.events += 1;
        out.push(TrackerMessage::Event(e));
    }

    fn line(&mut self, chunk: LineChunk<'_>, out: &mut Vec<TrackerMessage>) {
        self.counters.lines += 1;
        let parsed = match chunk {
            LineChunk::TooLong => Err(TrackerError::TooLong),
            LineChunk::Line(bytes) => parse_line(bytes),
        };
        match parsed {
            Ok(TrackerLine::Empty) => {}
            Ok(TrackerLine::Header {
                found,
                tracked,
                t_us,
                updated,
            }) => {
                self.cut_short();
                let expected = tracked as usize;
                let p = Pending {
                    frame: TrackerFrame {
                        t_us,
                        found,
                        tracked,
                        updated,
                        robots: Vec::with_capacity(expected),
                    },
                    expected,
                    poisoned: false,
                };
                if expected == 0 {
                    self.finish(p, out);
                } else {
                    self.pending = Some(p);
                }
            }
            Ok(TrackerLine::Robot {
                id,
                x,
                y,
                yaw_deg,
                last_seen_us,
            }) => {
                let Some(p) = self.pending.as_mut() else {
                    self.error(TrackerError::OrphanRobot);
                    return;
                };
                let state = SlotPose::state_for(last_seen_us, p.frame.t_us);
                p.frame.robots.push(SlotPose {
                    id,
                    x,
                    y,
                    yaw_deg,
                    last_seen_us,
                    state,
                });
                self.complete_if_full(out);
            }
            Ok(TrackerLine::Calibrated) => self.event(TrackerEvent::Calibrated, out),
            Ok(TrackerLine::Closed) => self.event(TrackerEvent::Closed, out),
            Err(e) => {
                // A bad line inside a block stands in for one of its slots, so the block still ends
                // where the server meant it to; it is then dropped whole.
                let in_block = if let Some(p) = self.pending.as_mut() {
                    p.poisoned = true;
                    p.expected = p.expected.saturating_sub(1);
                    true
                } else {
                    false
                };
                self.error(e);
                if in_block {
                    self.complete_if_full(out);
                }
            }
        }
    }

    fn complete_if_full(&mut self, out: &mut Vec<TrackerMessage>) {
        if self
            .pending
            .as_ref()
            .is_some_and(|p| p.frame.robots.len() >= p.expected)
            && let Some(p) = self.pending.take()
        {
            self.finish(p, out);
        }
    }
}

/// Streaming parser of the position server's TCP stream.
#[derive(Debug, Default)]
pub struct StreamParser {
    lines: LineBuffer,
    asm: Assembler,
}

impl StreamParser {
    pub fn new() -> Self {
        Self::default()
    }

    /// A parser with a custom line-length limit.
    pub fn with_max_line(max_line: usize) -> Self {
        StreamParser {
            lines: LineBuffer::new(max_line),
            asm: Assembler::default(),
        }
    }

    /// Feeds bytes as read from the socket; complete frames and events are appended to `out`.
    pub fn feed_into(&mut self, bytes: &[u8], out: &mut Vec<TrackerMessage>) {
        self.asm.counters.bytes += bytes.len() as u64;
        let asm = &mut self.asm;
        self.lines.push(bytes, |chunk| asm.line(chunk, out));
    }

    /// Feeds bytes and returns what completed.
    pub fn feed(&mut self, bytes: &[u8]) -> Vec<TrackerMessage> {
        let mut out = Vec::new();
        self.feed_into(bytes, &mut out);
        out
    }

    /// Forgets any partial line and block, e.g. after a reconnection. Counters are kept.
    pub fn reset(&mut self) {
        let max = self.lines.max_line();
        self.lines = LineBuffer::new(max);
        if self.asm.pending.take().is_some() {
            self.asm.counters.dropped_frames += 1;
        }
    }

    pub fn counters(&self) -> ParserCounters {
        self.asm.counters
    }

    /// The most recent error, for diagnostics.
    pub fn last_error(&self) -> Option<&TrackerError> {
        self.asm.last_error.as_ref()
    }
}
