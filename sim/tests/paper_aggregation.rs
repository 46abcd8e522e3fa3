//! Algorithms 2 (leader) and 3 (follower) decision by decision, and the sign of eq. (8).
use colcos_sim::behaviour::paper::*;
use colcos_sim::behaviour::{Behaviour, Observation};
use colcos_sim::rng;
use std::f32::consts::{FRAC_PI_2, PI};

/// Red and green per sensor (right, front, left, back).
fn obs(red: [f32; 4], green: [f32; 4]) -> Observation {
    let mut o = Observation {
        time: 1.0,
        ..Observation::default()
    };
    for n in 0..4 {
        o.intensity[n][RED] = red[n];
        o.intensity[n][GREEN] = green[n];
    }
    o
}

fn params() -> AggregationParams {
    FollowerParams::default().validate("robots[0]").unwrap()
}

#[test]
fn eq8_turns_toward_the_direction() {
    // Positive (counter-clockwise, to the left): the right wheel is faster.
    let c = eq8(0.5, 0.03, 0.08);
    assert!(c.right > c.left);
    let c = eq8(-0.5, 0.03, 0.08);
    assert!(c.left > c.right);
    // Straight ahead: both at the base speed.
    let c = eq8(0.0, 0.03, 0.08);
    assert_eq!((c.left, c.right), (0.08, 0.08));
    // Angles are wrapped: 3 pi / 2 is -pi / 2.
    let (a, b) = (eq8(1.5 * PI, 0.03, 0.08), eq8(-FRAC_PI_2, 0.03, 0.08));
    assert!((a.left - b.left).abs() < 1e-6 && (a.right - b.right).abs() < 1e-6);
}

#[test]
fn follower_climbs_the_agp_gradient() {
    let f = Follower::new(params());
    // AGP stronger on the left sensor: approach toward +pi/2 (left).
    let d = f.decide(&obs([0.0; 4], [0.5, 0.6, 0.7, 0.6]));
    let AggregationDecision::Approach { direction } = d else {
        panic!("{d:?}")
    };
    assert!((direction - FRAC_PI_2).abs() < 1e-5, "{direction}");
}

#[test]
fn follower_flees_down_the_alp_gradient_first() {
    let f = Follower::new(params());
    // ALP stronger at the front, AGP on the left: the alarm wins, and the robot heads backward.
    let d = f.decide(&obs([0.5, 0.7, 0.5, 0.3], [0.5, 0.6, 0.7, 0.6]));
    let AggregationDecision::Flee { direction } = d else {
        panic!("{d:?}")
    };
    assert!((direction.abs() - PI).abs() < 1e-5, "{direction}");
    // ALP on the right: flee to the left.
    let d = f.decide(&obs([0.7, 0.5, 0.3, 0.5], [0.0; 4]));
    let AggregationDecision::Flee { direction } = d else {
        panic!("{d:?}")
    };
    assert!((direction - FRAC_PI_2).abs() < 1e-5, "{direction}");
    let mut fl = Follower::new(params());
    let c = fl.act(
        &obs([0.7, 0.5, 0.3, 0.5], [0.0; 4]),
        &mut rng::stream(1, 0, 0),
    );
    assert!(
        c.right > c.left,
        "turns left, away from the alarm on the right: {c:?}"
    );
}

#[test]
fn follower_wanders_with_nothing_sensed_and_avoids_on_a_bump() {
    let f = Follower::new(params());
    assert_eq!(
        f.decide(&obs([0.0; 4], [0.0; 4])),
        AggregationDecision::Wander
    );
    let mut o = obs([0.7, 0.5, 0.3, 0.5], [0.5; 4]);
    o.bumpers = [0.5, 0.0, 0.0];
    assert_eq!(f.decide(&o), AggregationDecision::Avoid);
}

#[test]
fn leader_ignores_the_agp_and_flees_the_alp() {
    let l = Leader::new(LeaderParams::default().validate("robots[0]").unwrap());
    assert_eq!(
        l.decide(&obs([0.0; 4], [0.9, 0.9, 1.0, 0.9])),
        AggregationDecision::Wander
    );
    assert!(matches!(
        l.decide(&obs([0.3, 0.5, 0.3, 0.3], [0.0; 4])),
        AggregationDecision::Flee { .. }
    ));
    let mut o = obs([0.0; 4], [0.0; 4]);
    o.bumpers = [0.0, 0.9, 0.0];
    assert_eq!(l.decide(&o), AggregationDecision::Avoid);
}

#[test]
fn registry_refuses_unknown_keys() {
    let t: toml::Table = toml::from_str("attract_threshold = 0.1").unwrap();
    // The leader has no AGP threshold.
    assert!(colcos_sim::behaviour::registry::build("aggregation_leader", &t, "robots[0]").is_err());
    assert!(
        colcos_sim::behaviour::registry::build("aggregation_follower", &t, "robots[0]").is_ok()
    );
}
