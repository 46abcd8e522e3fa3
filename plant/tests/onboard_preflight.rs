//! The pre-flight check of a policy exported to run on board: the shield can only stop it.
use colcos_sim::scenario::Scenario;
use std::path::{Path, PathBuf};

fn fixture() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../bridge/tests/data/onboard/policy.json")
}

/// Three robots heading along x from `x`; the rig's shield caps the wheels at 0.2 m/s.
fn scenario_at(onboard: &Path, x: f32) -> Scenario {
    let text = format!(
        r#"
name = "onboard"
duration = 60.0
dt = 0.02
seed = 3
[screen]
resolution = [960, 540]
size = [1.439, 0.809]
[[robots]]
count = 3
behaviour = "wander"
placement = "explicit"
poses = [[{x}, 0.2, 0.0], [{x}, 0.4, 0.0], [{x}, 0.6, 0.0]]
[rig]
onboard = {onboard:?}
[rig.shield]
max_wheel_speed = 0.2
"#
    );
    Scenario::from_toml_str(&text, ".").unwrap()
}

/// The shield cannot steer a policy on board, only stop it: robots driving at a wall are held at the
/// virtual wall (and stay held, since their policy's last choice would still cross it), never reach the
/// arena's edge, and the pre-flight check refuses the policy naming the limit.
#[test]
fn the_shield_holds_robots_on_board_at_the_virtual_wall() {
    let sc = scenario_at(&fixture(), 1.3);
    let limits = colcos_plant::preflight::PreflightLimits::default();
    let r = colcos_plant::preflight::check(&sc, 1, 3.0, &limits).unwrap();
    assert_eq!(r.boundary, 0, "{r:?}");
    assert!(r.walled as f64 > 0.3 * r.robot_ticks as f64, "{r:?}");
    assert!(r.broken.iter().any(|b| b.starts_with("walled")), "{r:?}");
}
