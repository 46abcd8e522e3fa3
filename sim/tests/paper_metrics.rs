//! S(t) of eq. (9), arrivals and phases on known values.
use colcos_sim::Vec2;
use colcos_sim::metrics::*;

#[test]
fn sum_distance_on_known_positions() {
    let leader = Vec2::new(0.0, 0.0);
    let f = [
        Vec2::new(3.0, 4.0),
        Vec2::new(0.0, 1.0),
        Vec2::new(-2.0, 0.0),
    ];
    assert!((sum_distance(leader, f) - 8.0).abs() < 1e-6);
    let all = [leader, f[0], f[1], f[2], Vec2::new(100.0, 0.0)];
    // The predator (index 4) is not a follower.
    assert!((sum_distance_of(&all, 0, &[1, 2, 3]) - 8.0).abs() < 1e-6);
    assert_eq!(sum_distance_of(&all, 0, &[]), 0.0);
}

#[test]
fn arrival_picks_the_nearest_point_in_range() {
    let ends = [Vec2::new(0.0, 0.0), Vec2::new(0.05, 0.0)];
    assert_eq!(arrival(Vec2::new(0.04, 0.0), &ends, 0.03), Some(1));
    assert_eq!(arrival(Vec2::new(0.02, 0.0), &ends, 0.03), Some(0));
    assert_eq!(arrival(Vec2::new(0.5, 0.5), &ends, 0.03), None);
}

#[test]
fn tally_counts_arrivals_and_timeouts() {
    let o = [
        TrialOutcome::Arrived {
            point: 2,
            time: 1.0,
        },
        TrialOutcome::Arrived {
            point: 2,
            time: 2.0,
        },
        TrialOutcome::Arrived {
            point: 0,
            time: 2.0,
        },
        TrialOutcome::TimedOut,
    ];
    let c = ArrivalCounts::tally(&o, 4);
    assert_eq!(c.per_point, vec![1, 0, 2, 0]);
    assert_eq!(c.timeouts, 1);
    assert_eq!(
        (
            c.arrived(),
            c.trials(),
            c.at(&[2, 3]),
            c.distinct_points(),
            c.max_at_one_point()
        ),
        (3, 4, 2, 2, 2)
    );
}

#[test]
fn phases_split_on_the_alarm() {
    let t = [0.0, 1.0, 2.0, 3.0, 4.0, 5.0];
    let a = [false, false, true, true, false, false];
    let p = phases(&t, &a);
    assert_eq!(p.len(), 3);
    assert_eq!(
        (p[0].kind, p[0].start, p[0].end, p[0].first, p[0].last),
        (PhaseKind::Aggregation, 0.0, 2.0, 0, 1)
    );
    assert_eq!(
        (p[1].kind, p[1].start, p[1].end, p[1].first, p[1].last),
        (PhaseKind::Dispersion, 2.0, 4.0, 2, 3)
    );
    assert_eq!(
        (p[2].kind, p[2].start, p[2].end),
        (PhaseKind::Aggregation, 4.0, 5.0)
    );
    assert!(phases(&[], &[]).is_empty());
}

#[test]
fn relative_fall_and_rise() {
    let s = [2.0, 1.5, 0.5, 0.8, 2.5];
    assert!((relative_fall(&s, 0, 3) - 0.75).abs() < 1e-6);
    assert!((relative_rise(&s, 2, 4) - 4.0).abs() < 1e-6);
    assert_eq!(relative_fall(&[0.0, 1.0], 0, 1), 0.0);
    assert_eq!(relative_rise(&s, 9, 12), 0.0);
}
