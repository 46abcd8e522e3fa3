//! The Colias serial framing in both directions: any bytes, split anywhere, never panic, the frames
//! found do not depend on the split, and every payload decodes and encodes back to the same bytes.
#![no_main]
use colcos_bridge::protocol::colias::{CommandPacket, FrameDecoder, Telemetry};
use libfuzzer_sys::fuzz_target;

/// The frames of `N` bytes in `bytes`, checked to be the same fed whole and `step` bytes at a time
/// (`what` names them in the failure).
fn frames<const N: usize>(bytes: &[u8], step: usize, what: &str) -> Vec<[u8; N]> {
    let whole = FrameDecoder::<N>::new().feed(bytes);
    let mut decoder = FrameDecoder::<N>::new();
    let mut pieces = Vec::new();
    for chunk in bytes.chunks(step) {
        decoder.feed_into(chunk, &mut pieces);
    }
    assert_eq!(pieces, whole, "{what} split every {step} bytes");
    whole
}

fuzz_target!(|data: &[u8]| {
    let Some((&split, bytes)) = data.split_first() else {
        return;
    };
    let step = usize::from(split % 41) + 1;

    for payload in &frames(bytes, step, "telemetry") {
        assert_eq!(&Telemetry::decode(payload).encode(), payload);
    }

    for payload in &frames(bytes, step, "commands") {
        if let Ok(packet) = CommandPacket::decode(payload) {
            let bytes = packet.encode();
            let again = CommandPacket::decode(&bytes).expect("an encoded packet decodes");
            assert_eq!(again.encode(), bytes);
        }
    }
});
