//! The JSON pose datagrams: any bytes never panic; an accepted pose is finite, in range, and its
//! JSON parses back to the same pose.
#![no_main]
use colcos_bridge::protocol::udp_pose::JsonPose;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(pose) = JsonPose::parse(data) {
        assert!(
            [pose.x, pose.y, pose.heading, pose.t]
                .iter()
                .all(|v| v.is_finite())
        );
        let again = JsonPose::parse(pose.to_json().as_bytes()).expect("its own JSON parses");
        assert_eq!(again, pose);
    }
    let _ = JsonPose::parse_lines(data);
});
