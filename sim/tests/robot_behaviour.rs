//! Wander and Avoid.
use colcos_sim::behaviour::{Avoid, Behaviour, Observation, Wander, WheelCommand};
use colcos_sim::rng;

const DT: f32 = 0.02;

fn obs(time: f32, bumpers: [f32; 3]) -> Observation {
    Observation {
        time,
        bumpers,
        ..Observation::default()
    }
}

#[test]
fn wander_is_a_correlated_random_walk() {
    let mut w = Wander::new(0.1);
    let mut r = rng::stream(3, 0, 0);
    let n = 50_000;
    let turns: Vec<f32> = (0..n)
        .map(|k| {
            let c = w.act(&obs(k as f32 * DT, [0.0; 3]), &mut r);
            assert!(((c.left + c.right) / 2.0 - 0.1).abs() < 1e-6);
            (c.right - c.left) / (c.left + c.right)
        })
        .collect();
    let mean = turns.iter().sum::<f32>() / n as f32;
    let sd = (turns.iter().map(|t| (t - mean).powi(2)).sum::<f32>() / n as f32).sqrt();
    assert!(mean.abs() < 0.02, "mean {mean}");
    assert!((sd - w.turn_std).abs() < 0.02, "sd {sd}");
    // Correlated: consecutive turns are close (lag-1 correlation exp(-dt / 1 s) = 0.98).
    let lag1: f32 = turns
        .windows(2)
        .map(|p| (p[0] - mean) * (p[1] - mean))
        .sum::<f32>()
        / (n - 1) as f32
        / (sd * sd);
    assert!(
        (lag1 - (-DT / w.turn_time).exp()).abs() < 0.02,
        "lag-1 {lag1}"
    );
}

#[test]
fn wander_repeats_with_the_same_stream() {
    let run = || {
        let mut w = Wander::new(0.1);
        let mut r = rng::stream(4, 0, 0);
        (0..100)
            .map(|k| w.act(&obs(k as f32 * DT, [0.0; 3]), &mut r))
            .collect::<Vec<_>>()
    };
    assert_eq!(run(), run());
}

struct Forward;
impl Behaviour for Forward {
    fn name(&self) -> &str {
        "forward"
    }
    fn act(&mut self, _obs: &Observation, _rng: &mut rng::SimRng) -> WheelCommand {
        WheelCommand::new(0.1, 0.1)
    }
}

#[test]
fn avoid_turns_away_for_a_while_then_delegates() {
    let mut a = Avoid::new(Forward);
    let mut r = rng::stream(1, 0, 0);
    assert_eq!(
        a.act(&obs(0.0, [0.0; 3]), &mut r),
        WheelCommand::new(0.1, 0.1)
    );
    // Obstacle on the left: pivot right (clockwise: left wheel forward, right back).
    let c = a.act(&obs(1.0, [0.5, 0.2, 0.0]), &mut r);
    assert!(c.left > 0.0 && c.right < 0.0 && c.left == -c.right, "{c:?}");
    // The turn goes on after the bumper clears...
    let mut t = 1.0;
    while t < 1.0 + a.turn_duration - 1e-3 {
        assert_eq!(a.act(&obs(t, [0.0; 3]), &mut r), c, "at {t}");
        t += DT;
    }
    // ...and ends after its duration.
    assert_eq!(
        a.act(&obs(1.0 + a.turn_duration + 1e-3, [0.0; 3]), &mut r),
        WheelCommand::new(0.1, 0.1)
    );
    // Obstacle on the right, or dead ahead: pivot left.
    let c = a.act(&obs(3.0, [0.0, 0.0, 0.3]), &mut r);
    assert!(c.left < 0.0 && c.right > 0.0, "{c:?}");
    let c = a.act(&obs(5.0, [0.0, 0.5, 0.0]), &mut r);
    assert!(c.left < 0.0 && c.right > 0.0, "{c:?}");
    // Below the threshold: ignored.
    assert_eq!(
        a.act(&obs(7.0, [0.05, 0.05, 0.0]), &mut r),
        WheelCommand::new(0.1, 0.1)
    );
}
