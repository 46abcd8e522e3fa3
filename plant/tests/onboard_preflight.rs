//! The pre-flight check of a policy exported to run on board: the shield can only stop it.
use colcos_testkit::scenarios::{onboard, onboard_policy};

/// The shield cannot steer a policy on board, only stop it: robots driving at a wall are held at the
/// virtual wall (and stay held, since their policy's last choice would still cross it), never reach the
/// arena's edge, and the pre-flight check refuses the policy naming the limit.
#[test]
fn the_shield_holds_robots_on_board_at_the_virtual_wall() {
    // Three robots heading along x from 1.3 m; the rig's shield caps the wheels at 0.2 m/s.
    let sc = onboard(&onboard_policy(), 1.3);
    let limits = colcos_plant::preflight::PreflightLimits::default();
    let r = colcos_plant::preflight::check(&sc, 1, 3.0, &limits).unwrap();
    assert_eq!(r.counts.boundary, 0, "{r:?}");
    assert!(
        r.counts.walled as f64 > 0.3 * r.counts.robot_ticks as f64,
        "{r:?}"
    );
    assert!(r.broken.iter().any(|b| b.starts_with("walled")), "{r:?}");
}
