//! The robot-to-host telemetry payload: 96 bytes, Python struct `'=1B1L2B3h6H2H12H9f7B'`,
//! little-endian, decoded into named fields and encoded back (for the twin).

use super::TELEMETRY_LEN;

/// One telemetry packet. Every 96-byte payload decodes; there is nothing to validate.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Telemetry {
    pub id: u8,
    /// Robot clock, ms.
    pub sys_t_ms: u32,
    pub v_bat: u8,
    pub current: u8,
    pub yaw: i16,
    pub pitch: i16,
    pub roll: i16,
    /// IR bumpers with the emitter on: left, middle, right.
    pub tcrt_on: [u16; 3],
    /// IR bumpers with the emitter off: left, middle, right.
    pub tcrt_off: [u16; 3],
    /// Proximity/ambient sensors: left, right.
    pub apds: [u16; 2],
    /// Colour sensors in wire order front, back, left, right; each R, G, B counts.
    pub colour: [[u16; 3]; 4],
    /// On-board controller state (energy, avoidance and gathering forces, state, ...).
    pub controller: [f32; 9],
    pub reserved: [u8; 7],
}

/// A little-endian cursor over a fixed payload; offsets are compile-time-sized so reads cannot fail.
struct Reader<'a> {
    p: &'a [u8; TELEMETRY_LEN],
    at: usize,
}

impl Reader<'_> {
    fn take<const K: usize>(&mut self) -> [u8; K] {
        let mut b = [0u8; K];
        b.copy_from_slice(&self.p[self.at..self.at + K]);
        self.at += K;
        b
    }
    fn u8(&mut self) -> u8 {
        self.take::<1>()[0]
    }
    fn u16(&mut self) -> u16 {
        u16::from_le_bytes(self.take())
    }
    fn i16(&mut self) -> i16 {
        i16::from_le_bytes(self.take())
    }
    fn u32(&mut self) -> u32 {
        u32::from_le_bytes(self.take())
    }
    fn f32(&mut self) -> f32 {
        f32::from_le_bytes(self.take())
    }
}

struct Writer {
    p: [u8; TELEMETRY_LEN],
    at: usize,
}

impl Writer {
    fn put(&mut self, b: &[u8]) {
        self.p[self.at..self.at + b.len()].copy_from_slice(b);
        self.at += b.len();
    }
}

impl Telemetry {
    pub fn decode(p: &[u8; TELEMETRY_LEN]) -> Telemetry {
        let mut r = Reader { p, at: 0 };
        let id = r.u8();
        let sys_t_ms = r.u32();
        let v_bat = r.u8();
        let current = r.u8();
        let yaw = r.i16();
        let pitch = r.i16();
        let roll = r.i16();
        let tcrt_on = [r.u16(), r.u16(), r.u16()];
        let tcrt_off = [r.u16(), r.u16(), r.u16()];
        let apds = [r.u16(), r.u16()];
        let mut colour = [[0u16; 3]; 4];
        for s in &mut colour {
            for c in s.iter_mut() {
                *c = r.u16();
            }
        }
        let mut controller = [0f32; 9];
        for c in &mut controller {
            *c = r.f32();
        }
        let reserved = r.take::<7>();
        debug_assert_eq!(r.at, TELEMETRY_LEN);
        Telemetry {
            id,
            sys_t_ms,
            v_bat,
            current,
            yaw,
            pitch,
            roll,
            tcrt_on,
            tcrt_off,
            apds,
            colour,
            controller,
            reserved,
        }
    }

    pub fn encode(&self) -> [u8; TELEMETRY_LEN] {
        let mut w = Writer {
            p: [0u8; TELEMETRY_LEN],
            at: 0,
        };
        w.put(&[self.id]);
        w.put(&self.sys_t_ms.to_le_bytes());
        w.put(&[self.v_bat, self.current]);
        for v in [self.yaw, self.pitch, self.roll] {
            w.put(&v.to_le_bytes());
        }
        for v in self.tcrt_on.iter().chain(&self.tcrt_off).chain(&self.apds) {
            w.put(&v.to_le_bytes());
        }
        for v in self.colour.iter().flatten() {
            w.put(&v.to_le_bytes());
        }
        for v in &self.controller {
            w.put(&v.to_le_bytes());
        }
        w.put(&self.reserved);
        debug_assert_eq!(w.at, TELEMETRY_LEN);
        w.p
    }

    /// The whole frame, header and trailer included.
    pub fn to_frame(&self) -> Vec<u8> {
        super::encode_frame(&self.encode())
    }
}
