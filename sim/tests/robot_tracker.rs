//! Tracker model: latency, frame rate, noise, dropout.
use colcos_sim::rng;
use colcos_sim::robot::Pose;
use colcos_sim::tracker::{Tracker, TrackerParams};

const DT: f32 = 0.02;

fn quiet(rate_hz: f32, latency: f32) -> TrackerParams {
    TrackerParams {
        rate_hz,
        latency,
        position_noise: 0.0,
        heading_noise: 0.0,
        dropout: 0.0,
    }
}

#[test]
fn first_call_reports_the_true_poses() {
    let mut t = Tracker::new(TrackerParams::default(), 2);
    let mut r = rng::stream(1, 0, 0);
    let truth = [Pose::new(0.1, 0.2, 0.3), Pose::new(0.4, 0.5, 0.6)];
    let out = t.update(0.0, &truth, &mut r);
    assert!(out.iter().all(|p| p.seen));
    assert_eq!(out[0].pose, truth[0]);
    assert_eq!(out[1].pose, truth[1]);
}

#[test]
fn a_moving_robot_is_tracked_latency_behind() {
    let (rate, latency, v) = (30.0, 0.06, 0.1);
    let mut t = Tracker::new(quiet(rate, latency), 1);
    let mut r = rng::stream(1, 0, 0);
    let mut stamps = Vec::new();
    for k in 0..500 {
        let time = k as f32 * DT;
        let out = t.update(time, &[Pose::new(v * time, 0.5, 0.0)], &mut r)[0];
        if time > 0.2 {
            let lag = time - out.stamp;
            // Delivered `latency` after capture; the newest delivered frame is at most one frame
            // period (plus one step for the capture at the step after the frame time) older.
            assert!(lag >= latency - 1e-4, "lag {lag} at {time}");
            assert!(
                lag <= latency + 1.0 / rate + DT + 1e-4,
                "lag {lag} at {time}"
            );
            // The pose is the true pose at the stamp.
            assert!((v * out.stamp - out.pose.pos.x).abs() < 1e-5);
            if stamps.last() != Some(&out.stamp) {
                stamps.push(out.stamp);
            }
        }
    }
    // Frames due at 30 Hz, taken at 50 Hz steps: stamps one or two steps apart, 30 per second overall.
    for w in stamps.windows(2) {
        let gap = ((w[1] - w[0]) / DT).round();
        assert!(gap == 1.0 || gap == 2.0, "{w:?}");
    }
    let span = stamps.last().unwrap() - stamps[0];
    let frames = (stamps.len() - 1) as f32;
    assert!(
        (frames - span * rate).abs() <= 1.0,
        "{frames} frames in {span} s"
    );
}

#[test]
fn zero_latency_at_the_step_rate_is_the_truth() {
    let mut t = Tracker::new(quiet(50.0, 0.0), 1);
    let mut r = rng::stream(1, 0, 0);
    for k in 0..100 {
        let time = k as f32 * DT;
        let truth = Pose::new(0.1 * time, 0.5, time);
        let out = t.update(time, &[truth], &mut r)[0];
        assert_eq!(out.pose, truth);
    }
}

#[test]
fn noise_and_dropout_statistics() {
    let params = TrackerParams {
        rate_hz: 50.0,
        latency: 0.0,
        position_noise: 0.002,
        heading_noise: 0.03,
        dropout: 0.1,
    };
    let n = 200;
    let mut t = Tracker::new(params, n);
    let mut r = rng::stream(5, 0, 0);
    let truth: Vec<Pose> = (0..n)
        .map(|i| Pose::new(i as f32 * 0.01, 0.5, 0.0))
        .collect();
    t.update(0.0, &truth, &mut r);
    let (mut dx, mut dh, mut count) = (0.0f64, 0.0f64, 0usize);
    let (mut same, mut total) = (0usize, 0usize);
    let mut prev: Vec<Pose> = t
        .update(0.0, &truth, &mut r)
        .iter()
        .map(|p| p.pose)
        .collect();
    for k in 1..500 {
        let out = t.update(k as f32 * DT, &truth, &mut r);
        for (i, p) in out.iter().enumerate() {
            let e = p.pose.pos - truth[i].pos;
            dx += (e.x as f64).powi(2) + (e.y as f64).powi(2);
            dh += (p.pose.heading as f64).powi(2);
            count += 1;
            // A dropped robot keeps its previous pose exactly.
            if p.pose == prev[i] {
                same += 1;
            }
            total += 1;
            prev[i] = p.pose;
        }
    }
    let sd_pos = (dx / (2 * count) as f64).sqrt();
    let sd_head = (dh / count as f64).sqrt();
    let rate = same as f64 / total as f64;
    assert!((sd_pos - 0.002).abs() < 0.0001, "position sd {sd_pos}");
    assert!((sd_head - 0.03).abs() < 0.0015, "heading sd {sd_head}");
    assert!((rate - 0.1).abs() < 0.01, "dropout {rate}");
}

#[test]
fn tracker_is_deterministic() {
    let run = || {
        let mut t = Tracker::new(TrackerParams::default(), 3);
        let mut r = rng::stream(2, 0, 0);
        let truth = [
            Pose::new(0.1, 0.2, 0.3),
            Pose::new(0.4, 0.5, 0.6),
            Pose::new(0.7, 0.1, 0.0),
        ];
        (0..200)
            .map(|k| t.update(k as f32 * DT, &truth, &mut r).to_vec())
            .collect::<Vec<_>>()
    };
    assert_eq!(run(), run());
}
