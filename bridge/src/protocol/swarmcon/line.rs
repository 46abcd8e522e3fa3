//! Splits an arbitrary byte stream into `\n`-terminated lines with a bounded buffer.

use super::MAX_LINE;

/// A line or a dropped over-long line, as produced by [`LineBuffer::push`].
#[derive(Debug, PartialEq, Eq)]
pub(crate) enum LineChunk<'a> {
    /// One line without its `\n` (a trailing `\r` is kept; the parser ignores it).
    Line(&'a [u8]),
    /// A line exceeded the limit and was discarded up to its `\n`.
    TooLong,
}

/// Accumulates partial lines across reads; never holds more than `max_line` bytes.
#[derive(Debug)]
pub(crate) struct LineBuffer {
    partial: Vec<u8>,
    max_line: usize,
    /// Dropping bytes until the next `\n` because the current line is too long.
    discarding: bool,
}

impl Default for LineBuffer {
    fn default() -> Self {
        Self::new(MAX_LINE)
    }
}

impl LineBuffer {
    pub(crate) fn new(max_line: usize) -> Self {
        LineBuffer {
            partial: Vec::new(),
            max_line: max_line.max(1),
            discarding: false,
        }
    }

    pub(crate) fn max_line(&self) -> usize {
        self.max_line
    }

    /// Feeds bytes and calls `f` for every complete line, in order. Lines wholly inside `bytes` are
    /// passed without copying.
    pub(crate) fn push(&mut self, mut bytes: &[u8], mut f: impl FnMut(LineChunk<'_>)) {
        while !bytes.is_empty() {
            let Some(nl) = bytes.iter().position(|&b| b == b'\n') else {
                self.keep_partial(bytes);
                return;
            };
            let (head, rest) = (&bytes[..nl], &bytes[nl + 1..]);
            bytes = rest;
            if self.discarding {
                self.discarding = false;
                f(LineChunk::TooLong);
                continue;
            }
            if self.partial.is_empty() {
                if head.len() > self.max_line {
                    f(LineChunk::TooLong);
                } else {
                    f(LineChunk::Line(head));
                }
            } else if self.partial.len() + head.len() > self.max_line {
                self.partial.clear();
                f(LineChunk::TooLong);
            } else {
                self.partial.extend_from_slice(head);
                f(LineChunk::Line(&self.partial));
                self.partial.clear();
            }
        }
    }

    fn keep_partial(&mut self, bytes: &[u8]) {
        if self.discarding {
            return;
        }
        if self.partial.len() + bytes.len() > self.max_line {
            // Reported once, when the line finally ends; until then the bytes are ignored.
            self.partial.clear();
            self.discarding = true;
            return;
        }
        self.partial.extend_from_slice(bytes);
    }
}
