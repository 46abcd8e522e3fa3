//! JSON pose messages: arbitrary bytes never panic, and every valid pose survives a round trip.

use colcos_bridge::protocol::udp_pose::JsonPose;
use proptest::prelude::*;

proptest! {
    #[test]
    fn arbitrary_bytes_never_panic(bytes in prop::collection::vec(any::<u8>(), 0..300)) {
        let _ = JsonPose::parse(&bytes);
        let _ = JsonPose::parse_lines(&bytes);
    }

    #[test]
    fn valid_poses_round_trip(id in any::<u32>(), x in -1000.0f64..1000.0, y in -1000.0f64..1000.0, heading in -7.0f64..7.0, t in 0.0f64..1e9) {
        let p = JsonPose { id, x, y, heading, t };
        let q = JsonPose::parse(p.to_json().as_bytes()).map_err(|e| TestCaseError::fail(e.to_string()))?;
        // serde_json's default float parser may be one ulp off; exact round trips are not needed.
        let close = |a: f64, b: f64| (a - b).abs() <= 4.0 * f64::EPSILON * a.abs().max(1.0);
        prop_assert_eq!(q.id, id);
        prop_assert!(close(q.x, x) && close(q.y, y) && close(q.heading, heading) && close(q.t, t), "{:?} vs {:?}", q, p);
    }
}
