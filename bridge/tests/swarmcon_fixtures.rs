//! Byte-for-byte fixtures of the position server's stream, written from the documented C formats.

use colcos_bridge::protocol::swarmcon::{
    Calibrate, HeaderForm, SlotState, StreamParser, TrackerEvent, TrackerFrame, TrackerMessage,
    write_block,
};

fn frames(msgs: &[TrackerMessage]) -> Vec<&TrackerFrame> {
    msgs.iter()
        .filter_map(|m| match m {
            TrackerMessage::Frame(f) => Some(f),
            _ => None,
        })
        .collect()
}

/// The frames a fresh parser makes of `bytes`, and the parser (for its counters).
fn parse_frames(bytes: &[u8]) -> (Vec<TrackerFrame>, StreamParser) {
    let mut p = StreamParser::new();
    let out = p.feed(bytes);
    let f = frames(&out).into_iter().cloned().collect();
    (f, p)
}

const PLAIN: &[u8] = b"Detected 2 of 3 at 1700000000123456 \n\
Robot 000 0.512 0.300 45.000 1700000000123456 \n\
Robot 001 -0.020 -0.105 -179.500 1700000000100000 \n\
Robot -01 1.250 0.700 0.000 -1 \n";

#[test]
fn plain_header_with_fresh_stale_never_seen_and_unidentified() {
    let (f, p) = parse_frames(PLAIN);
    assert_eq!(f.len(), 1);
    let f = &f[0];
    assert_eq!(
        (f.found, f.tracked, f.t_us, f.updated),
        (2, 3, 1_700_000_000_123_456, None)
    );
    assert_eq!(f.robots.len(), 3);
    assert_eq!(f.robots[0].id, 0);
    assert_eq!(
        (f.robots[0].x, f.robots[0].y, f.robots[0].yaw_deg),
        (0.512, 0.3, 45.0)
    );
    assert_eq!(f.robots[0].state, SlotState::Fresh);
    assert_eq!(
        (f.robots[1].x, f.robots[1].y, f.robots[1].yaw_deg),
        (-0.02, -0.105, -179.5)
    );
    assert_eq!(f.robots[1].state, SlotState::Stale);
    assert_eq!(f.robots[2].id, -1);
    assert!(!f.robots[2].is_identified());
    assert_eq!(f.robots[2].last_seen_us, -1);
    assert_eq!(f.robots[2].state, SlotState::NeverSeen);
    assert_eq!(p.counters().errors, 0);
}

#[test]
fn dot_header() {
    let (f, _) = parse_frames(b"Detected 1 of 1 at 42. \nRobot 007 0.100 0.200 3.000 42 \n");
    assert_eq!(f.len(), 1);
    assert_eq!((f[0].t_us, f[0].updated, f[0].robots[0].id), (42, None, 7));
}

#[test]
fn updated_header() {
    let (f, _) = parse_frames(b"Detected 1 of 2 at 99, 1 updated. \nRobot 003 0.100 0.200 3.000 99 \nRobot 004 0.300 0.400 5.000 98 \n");
    assert_eq!(f.len(), 1);
    assert_eq!((f[0].t_us, f[0].updated), (99, Some(1)));
    assert_eq!(f[0].robots[1].state, SlotState::Stale);
}

#[test]
fn repeated_blocks_repeat_frames_and_empty_blocks_emit() {
    let block = b"Detected 1 of 1 at 500 \nRobot 002 0.100 0.100 0.000 500 \n";
    let mut stream = block.repeat(3);
    stream.extend_from_slice(b"Detected 0 of 0 at 501 \n");
    let (f, _) = parse_frames(&stream);
    assert_eq!(f.len(), 4);
    assert_eq!(f[0], f[2]);
    assert!(f[3].robots.is_empty());
}

#[test]
fn repeated_slot_ids_are_kept_in_order() {
    let (f, _) = parse_frames(
        b"Detected 2 of 2 at 7 \nRobot 005 0.100 0.100 0.000 7 \nRobot 005 0.200 0.200 0.000 7 \n",
    );
    assert_eq!(
        f[0].robots.iter().map(|r| r.x).collect::<Vec<_>>(),
        vec![0.1, 0.2]
    );
}

#[test]
fn calibrated_and_closed_events() {
    let mut p = StreamParser::new();
    let out = p.feed(b"Detected 0 of 0 at 1 \nCalibrated\nDetected 0 of 0 at 2 \nClosed\n");
    assert!(matches!(out[0], TrackerMessage::Frame(_)));
    assert_eq!(out[1], TrackerMessage::Event(TrackerEvent::Calibrated));
    assert!(matches!(out[2], TrackerMessage::Frame(_)));
    assert_eq!(out[3], TrackerMessage::Event(TrackerEvent::Closed));
    assert_eq!(p.counters().errors, 0);
}

#[test]
fn truncated_block_is_dropped_and_counted() {
    let mut p = StreamParser::new();
    let out = p.feed(b"Detected 2 of 2 at 1 \nRobot 000 0.1 0.1 0.0 1 \nClosed\n");
    assert_eq!(out, vec![TrackerMessage::Event(TrackerEvent::Closed)]);
    assert_eq!(p.counters().dropped_frames, 1);
    assert_eq!(p.counters().errors, 1);
}

#[test]
fn garbage_invalid_utf8_nan_and_absurd_numbers_are_counted() {
    let mut s = Vec::new();
    s.extend_from_slice(b"\xff\xfe garbage\n");
    s.extend_from_slice(b"hello world\n");
    s.extend_from_slice(b"Robot 001 0.1 0.1 0.0 1 \n"); // outside a block
    s.extend_from_slice(b"Detected 1 of 1 at 5 \nRobot 001 nan 0.1 0.0 5 \n");
    s.extend_from_slice(b"Detected 1 of 1 at 6 \nRobot 001 99999999.000 0.1 0.0 6 \n");
    s.extend_from_slice(b"Detected 1 of 99999 at 7 \n");
    s.extend_from_slice(b"Detected 1 of 1 at 8 \nRobot 001 0.100 0.100 0.000 8 \n");
    let (f, p) = parse_frames(&s);
    assert_eq!(f.len(), 1);
    assert_eq!(f[0].t_us, 8);
    assert_eq!(p.counters().errors, 6);
    assert_eq!(p.counters().dropped_frames, 2);
}

#[test]
fn over_long_lines_are_dropped_without_growing() {
    let mut p = StreamParser::new();
    let long = vec![b'x'; 100_000];
    for chunk in long.chunks(1000) {
        p.feed(chunk);
    }
    let out = p.feed(b"\nDetected 0 of 0 at 3 \n");
    assert_eq!(frames(&out).len(), 1);
    assert_eq!(p.counters().errors, 1);
}

#[test]
fn writer_matches_c_sprintf_bytes() {
    let (f, _) = parse_frames(PLAIN);
    let f = &f[0];
    assert_eq!(write_block(f, HeaderForm::Plain, false).as_bytes(), PLAIN);
    let dot = write_block(f, HeaderForm::Dot, true);
    assert!(dot.starts_with("Detected 2 of 3 at 1700000000123456. \n"));
    assert!(dot.ends_with(" -1 \nCalibrated\n"));
    let mut g = f.clone();
    g.updated = Some(2);
    assert!(
        write_block(&g, HeaderForm::Updated, false)
            .starts_with("Detected 2 of 3 at 1700000000123456, 2 updated. \n")
    );
}

#[test]
fn calibrate_command_encodes_and_parses() {
    let c = Calibrate {
        robots: 12,
        field_length: 1.439,
        field_width: 0.809,
        camera_height: 1.8,
        robot_diameter: 0.04,
        robot_height: 0.035,
    };
    let s = c.encode().unwrap();
    assert_eq!(s, "Calibrate 12 1.439 0.809 1.800 0.040 0.035 \n");
    assert_eq!(Calibrate::parse(s.as_bytes()).unwrap(), c);
    assert!(Calibrate::parse(b"Calibrate 12 1.4 nan 1.8 0.04 0.035 \n").is_err());
    assert!(Calibrate::parse(b"Calibrate x 1.4 0.8 1.8 0.04 0.035 \n").is_err());
    let bad = Calibrate {
        field_width: -1.0,
        ..c
    };
    assert!(
        bad.encode()
            .unwrap_err()
            .to_string()
            .contains("field width")
    );
}
