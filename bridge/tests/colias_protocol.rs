//! The Colias serial protocol: every telemetry field at its documented offset, command frames byte
//! for byte, and frame decoding under garbage and arbitrary splits.

use colcos_bridge::protocol::colias::{
    CommandDecoder, CommandPacket, HostCommand, MotionKind, TELEMETRY_LEN, Telemetry,
    TelemetryDecoder, colour_to_sim,
};
use proptest::prelude::*;

/// A payload laid out by hand from `'=1B1L2B3h6H2H12H9f7B'`.
fn fixture() -> [u8; TELEMETRY_LEN] {
    let mut b: Vec<u8> = Vec::new();
    b.push(17); // ID
    b.extend(123_456u32.to_le_bytes()); // SYS-T
    b.extend([200, 35]); // V-BAT, CURRENT
    for v in [-1234i16, 567, -89] {
        b.extend(v.to_le_bytes()); // YAW, PITCH, ROLL
    }
    for v in 1u16..=6 {
        b.extend((v * 100).to_le_bytes()); // TCRT-ON-L/M/R, TCRT-OFF-L/M/R
    }
    b.extend(4000u16.to_le_bytes()); // APDS-L
    b.extend(4001u16.to_le_bytes()); // APDS-R
    for v in 0u16..12 {
        b.extend((60_000 + v).to_le_bytes()); // COL-S-{F,B,L,R}-{R,G,B}
    }
    for k in 0..9 {
        b.extend((k as f32 * 0.5 - 1.0).to_le_bytes());
    }
    b.extend([1, 2, 3, 4, 5, 6, 7]);
    b.try_into().expect("96 bytes")
}

#[test]
fn every_telemetry_field_decodes_at_its_offset() {
    let p = fixture();
    let t = Telemetry::decode(&p);
    assert_eq!(t.id, 17);
    assert_eq!(t.sys_t_ms, 123_456);
    assert_eq!((t.v_bat, t.current), (200, 35));
    assert_eq!((t.yaw, t.pitch, t.roll), (-1234, 567, -89));
    assert_eq!(t.tcrt_on, [100, 200, 300]);
    assert_eq!(t.tcrt_off, [400, 500, 600]);
    assert_eq!(t.apds, [4000, 4001]);
    assert_eq!(t.colour[0], [60_000, 60_001, 60_002]); // front
    assert_eq!(t.colour[1], [60_003, 60_004, 60_005]); // back
    assert_eq!(t.colour[2], [60_006, 60_007, 60_008]); // left
    assert_eq!(t.colour[3], [60_009, 60_010, 60_011]); // right
    assert_eq!(
        t.controller,
        [-1.0, -0.5, 0.0, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0]
    );
    assert_eq!(t.reserved, [1, 2, 3, 4, 5, 6, 7]);
    assert_eq!(t.encode(), p);
    let sim = colour_to_sim(t.colour);
    assert_eq!((sim[0], sim[1]), (t.colour[3], t.colour[0]));
}

#[test]
fn command_frames_are_byte_exact() {
    let f = CommandPacket::new(
        200,
        1,
        HostCommand::Motion {
            kind: MotionKind::Stop,
            speed: 0.0,
        },
    )
    .to_frame();
    assert_eq!(f.len(), 36);
    assert_eq!(&f[..10], &[0x01, 0xFE, 200, 1, 0, 0, 0, b'M', b'S', b'P']);
    assert_eq!(&f[34..], &[0xFE, 0x01]);
    let w = CommandPacket::new(
        3,
        0,
        HostCommand::WheelSpeeds {
            left: 0.5,
            right: -0.5,
        },
    )
    .to_frame();
    assert_eq!(&w[7..18], &[b'M', b'W', b'S', 0, 0, 0, 0x3F, 0, 0, 0, 0xBF]);
}

fn telemetry() -> impl Strategy<Value = Telemetry> {
    (
        any::<[u8; 8]>(),
        any::<[u16; 12]>(),
        any::<[u16; 8]>(),
        prop::array::uniform9(-1e6f32..1e6),
    )
        .prop_map(|(b, colour, ir, controller)| Telemetry {
            id: b[0],
            sys_t_ms: u32::from_le_bytes([b[1], b[2], b[3], b[4]]),
            v_bat: b[5],
            current: b[6],
            yaw: b[7] as i16 - 100,
            pitch: -(b[7] as i16),
            roll: b[7] as i16,
            tcrt_on: [ir[0], ir[1], ir[2]],
            tcrt_off: [ir[3], ir[4], ir[5]],
            apds: [ir[6], ir[7]],
            colour: std::array::from_fn(|s| [colour[3 * s], colour[3 * s + 1], colour[3 * s + 2]]),
            controller,
            reserved: [b[0]; 7],
        })
}

proptest! {
    #[test]
    fn telemetry_round_trips_through_garbage_and_splits(
        packets in prop::collection::vec(telemetry(), 1..6),
        garbage in prop::collection::vec(prop::collection::vec(any::<u8>().prop_filter("no header byte", |b| *b != 0x01), 0..40), 6),
        cuts in prop::collection::vec(any::<usize>(), 0..10),
    ) {
        let mut stream = Vec::new();
        for (p, g) in packets.iter().zip(&garbage) {
            stream.extend(g);
            stream.extend(p.to_frame());
        }
        let mut cuts: Vec<usize> = cuts.iter().map(|c| c % (stream.len() + 1)).collect();
        cuts.sort_unstable();
        let mut d = TelemetryDecoder::new();
        let mut out = Vec::new();
        let mut start = 0;
        for c in cuts.into_iter().chain(std::iter::once(stream.len())) {
            d.feed_into(&stream[start..c], &mut out);
            start = c;
            prop_assert!(d.pending() < 4096 + 100);
        }
        let got: Vec<Telemetry> = out.iter().map(Telemetry::decode).collect();
        prop_assert_eq!(got, packets);
    }

    #[test]
    fn random_bytes_never_panic_and_stay_bounded(bytes in prop::collection::vec(any::<u8>(), 0..5000)) {
        let mut d = CommandDecoder::new();
        for p in d.feed(&bytes) {
            let _ = CommandPacket::decode(&p);
        }
        prop_assert!(d.pending() < 36);
    }
}
