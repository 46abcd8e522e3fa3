//! The SwarmCon tracker stream: any bytes, split anywhere, never panic, and the messages do not
//! depend on how the stream was split; every slot converts to a pose in the simulator's frame.
#![no_main]
use colcos_bridge::protocol::swarmcon::{
    Calibrate, FrameTransform, StreamParser, TrackerMessage, parse_line,
};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Some((&split, bytes)) = data.split_first() else {
        return;
    };
    let mut parser = StreamParser::with_max_line(64 + usize::from(split));
    let mut pieces = Vec::new();
    let step = usize::from(split % 17) + 1;
    for chunk in bytes.chunks(step) {
        parser.feed_into(chunk, &mut pieces);
    }
    let mut reference = StreamParser::with_max_line(64 + usize::from(split));
    let all_at_once = reference.feed(bytes);
    assert_eq!(
        format!("{pieces:?}"),
        format!("{all_at_once:?}"),
        "split every {step} bytes"
    );
    let transform = FrameTransform::with_offset(0.809, 0.02, 0.02);
    for message in &all_at_once {
        if let TrackerMessage::Frame(frame) = message {
            for slot in &frame.robots {
                let _ = transform.to_sim(slot);
            }
        }
    }
    for line in bytes.split(|&b| b == b'\n') {
        let _ = parse_line(line);
        if let Ok(c) = Calibrate::parse(line) {
            let _ = c.validate();
            let _ = c.encode();
        }
    }
});
