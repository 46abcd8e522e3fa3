//! The Colias serial framing in both directions: any bytes, split anywhere, never panic, the frames
//! found do not depend on the split, and every payload decodes and encodes back to the same bytes.
#![no_main]
use colcos_bridge::protocol::colias::{CommandDecoder, CommandPacket, Telemetry, TelemetryDecoder};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Some((&split, bytes)) = data.split_first() else {
        return;
    };
    let step = usize::from(split % 41) + 1;

    let whole = TelemetryDecoder::new().feed(bytes);
    let mut decoder = TelemetryDecoder::new();
    let mut pieces = Vec::new();
    for chunk in bytes.chunks(step) {
        decoder.feed_into(chunk, &mut pieces);
    }
    assert_eq!(pieces, whole, "telemetry split every {step} bytes");
    for payload in &whole {
        assert_eq!(&Telemetry::decode(payload).encode(), payload);
    }

    let whole = CommandDecoder::new().feed(bytes);
    let mut decoder = CommandDecoder::new();
    let mut pieces = Vec::new();
    for chunk in bytes.chunks(step) {
        decoder.feed_into(chunk, &mut pieces);
    }
    assert_eq!(pieces, whole, "commands split every {step} bytes");
    for payload in &whole {
        if let Ok(packet) = CommandPacket::decode(payload) {
            let bytes = packet.encode();
            let again = CommandPacket::decode(&bytes).expect("an encoded packet decodes");
            assert_eq!(again.encode(), bytes);
        }
    }
});
