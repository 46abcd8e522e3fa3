//! Property tests of the tracker stream parser: any byte stream, cut anywhere, never panics and gives
//! the same result as one read; what the writer writes, the parser reads back.

use colcos_bridge::protocol::swarmcon::{
    HeaderForm, SlotPose, StreamParser, TrackerFrame, TrackerMessage, write_block,
};
use proptest::prelude::*;

fn parse_split(bytes: &[u8], cuts: &[usize]) -> (Vec<TrackerMessage>, u64) {
    let mut p = StreamParser::with_max_line(64);
    let mut out = Vec::new();
    let mut cuts: Vec<usize> = cuts.iter().map(|c| c % (bytes.len() + 1)).collect();
    cuts.sort_unstable();
    let mut start = 0;
    for c in cuts.into_iter().chain(std::iter::once(bytes.len())) {
        p.feed_into(&bytes[start..c], &mut out);
        start = c;
    }
    (out, p.counters().errors)
}

fn slot() -> impl Strategy<Value = SlotPose> {
    (
        -1i32..200,
        -2000i32..2000,
        -2000i32..2000,
        -180_000i32..180_000,
        prop::bool::ANY,
        prop::bool::ANY,
    )
        .prop_map(|(id, x, y, yaw, fresh, never)| {
            let last = if never {
                -1
            } else if fresh {
                1000
            } else {
                999
            };
            SlotPose {
                id,
                x: x as f64 / 1000.0,
                y: y as f64 / 1000.0,
                yaw_deg: yaw as f64 / 1000.0,
                last_seen_us: last,
                state: SlotPose::state_for(last, 1000),
            }
        })
}

fn tracker_stream() -> impl Strategy<Value = Vec<u8>> {
    let frame = (prop::collection::vec(slot(), 0..6), 0usize..3).prop_map(|(robots, form)| {
        let form = [HeaderForm::Plain, HeaderForm::Dot, HeaderForm::Updated][form];
        let f = TrackerFrame {
            t_us: 1000,
            found: robots.len() as i32,
            tracked: robots.len() as i32,
            updated: (form == HeaderForm::Updated).then_some(1),
            robots,
        };
        write_block(&f, form, false).into_bytes()
    });
    let piece = prop_oneof![
        4 => frame,
        1 => prop::collection::vec(any::<u8>(), 0..80),
        1 => Just(b"Calibrated\n".to_vec()),
        1 => Just(b"Closed\n".to_vec()),
    ];
    prop::collection::vec(piece, 0..8).prop_map(|v| v.concat())
}

proptest! {
    #[test]
    fn any_split_gives_the_same_messages(bytes in tracker_stream(), cuts in prop::collection::vec(any::<usize>(), 0..12)) {
        let whole = parse_split(&bytes, &[]);
        let split = parse_split(&bytes, &cuts);
        prop_assert_eq!(whole, split);
    }

    #[test]
    fn random_bytes_never_panic(bytes in prop::collection::vec(any::<u8>(), 0..2000), cuts in prop::collection::vec(any::<usize>(), 0..12)) {
        let whole = parse_split(&bytes, &[]);
        let split = parse_split(&bytes, &cuts);
        prop_assert_eq!(whole, split);
    }

    #[test]
    fn writer_then_parser_round_trips(robots in prop::collection::vec(slot(), 0..20), form in 0usize..3) {
        let form = [HeaderForm::Plain, HeaderForm::Dot, HeaderForm::Updated][form];
        let f = TrackerFrame {
            t_us: 1000,
            found: 3,
            tracked: robots.len() as i32,
            updated: (form == HeaderForm::Updated).then_some(4),
            robots,
        };
        let mut p = StreamParser::new();
        let out = p.feed(write_block(&f, form, false).as_bytes());
        prop_assert_eq!(p.counters().errors, 0);
        prop_assert_eq!(out, vec![TrackerMessage::Frame(f)]);
    }
}
