//! Framing of the Colias serial protocol and a streaming decoder that resynchronises on garbage.

use super::{HEADER, TRAILER};

/// Wraps a payload in the header and trailer.
pub(crate) fn encode_frame<const N: usize>(payload: &[u8; N]) -> Vec<u8> {
    let mut v = Vec::with_capacity(N + 4);
    v.extend_from_slice(&HEADER);
    v.extend_from_slice(payload);
    v.extend_from_slice(&TRAILER);
    v
}

/// Running totals of a decoder.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct DecoderCounters {
    pub bytes: u64,
    pub frames: u64,
    /// Bytes discarded while looking for a valid frame.
    pub skipped: u64,
    /// Headers found whose trailer did not follow `N` bytes later.
    pub bad_trailers: u64,
}

/// Splits a byte stream into fixed-length payloads. With no length field or checksum the only check
/// is the trailer: find the header, take `N` bytes, check the trailer, else skip one byte.
#[derive(Debug)]
pub struct FrameDecoder<const N: usize> {
    buf: Vec<u8>,
    counters: DecoderCounters,
}

impl<const N: usize> Default for FrameDecoder<N> {
    fn default() -> Self {
        Self::new()
    }
}

/// Bytes taken from the input at a time, which bounds the buffer at this plus one frame.
const CHUNK: usize = 4096;

impl<const N: usize> FrameDecoder<N> {
    pub fn new() -> Self {
        FrameDecoder {
            buf: Vec::with_capacity(CHUNK + N + 4),
            counters: DecoderCounters::default(),
        }
    }

    pub fn counters(&self) -> DecoderCounters {
        self.counters
    }

    /// Bytes held waiting for the rest of a frame.
    pub fn pending(&self) -> usize {
        self.buf.len()
    }

    /// Feeds bytes; every complete, well-framed payload is appended to `out`.
    pub fn feed_into(&mut self, bytes: &[u8], out: &mut Vec<[u8; N]>) {
        self.counters.bytes += bytes.len() as u64;
        for chunk in bytes.chunks(CHUNK) {
            self.buf.extend_from_slice(chunk);
            self.scan(out);
        }
    }

    /// Feeds bytes and returns the payloads that completed.
    pub fn feed(&mut self, bytes: &[u8]) -> Vec<[u8; N]> {
        let mut out = Vec::new();
        self.feed_into(bytes, &mut out);
        out
    }

    fn scan(&mut self, out: &mut Vec<[u8; N]>) {
        let buf = &self.buf;
        let mut i = 0;
        loop {
            let Some(pos) = buf[i..].windows(2).position(|w| w == HEADER) else {
                // Keep a last 0x01: it may be the first half of a header.
                let keep = usize::from(buf.last() == Some(&HEADER[0]));
                let end = buf.len() - keep;
                self.counters.skipped += end.saturating_sub(i) as u64;
                i = end.max(i);
                break;
            };
            self.counters.skipped += pos as u64;
            i += pos;
            if buf.len() - i < N + 4 {
                break;
            }
            if buf[i + 2 + N..i + 4 + N] == TRAILER {
                let mut p = [0u8; N];
                p.copy_from_slice(&buf[i + 2..i + 2 + N]);
                out.push(p);
                self.counters.frames += 1;
                i += N + 4;
            } else {
                self.counters.bad_trailers += 1;
                self.counters.skipped += 1;
                i += 1;
            }
        }
        self.buf.drain(..i);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn resynchronises_after_garbage_and_false_headers() {
        let mut p = [7u8; 8];
        p[0] = 0x01;
        p[1] = 0xFE;
        let mut s = vec![0x55, 0x01, 0xFE, 0x01, 0x01];
        s.extend(encode_frame(&p));
        s.extend([0xFE, 0x01]);
        s.extend(encode_frame(&[9u8; 8]));
        let mut d = FrameDecoder::<8>::new();
        assert_eq!(d.feed(&s), vec![p, [9u8; 8]]);
        assert!(d.pending() < 12);
    }
}
