//! Colour sensor: counts, calibrated inverse, saturation, noise.
use colcos_sim::field::{FieldModel, GaussianField, GaussianSource, Pheromone};
use colcos_sim::rng;
use colcos_sim::screen::ScreenSpec;
use colcos_sim::sensors::{ColourSensor, ColourSensorParams, invert3};
use glam::Vec2;

fn quiet() -> ColourSensor {
    ColourSensor::new(ColourSensorParams {
        noise: 0.0,
        ..ColourSensorParams::default()
    })
}

#[test]
fn round_trip_over_all_levels() {
    let s = quiet();
    let mut r = rng::stream(1, 0, 0);
    let mut worst = 0.0f32;
    for level in 0..=255 {
        let l = level as f32;
        // Grey, single primaries, and mixed colours.
        let cases = [
            [l, l, l],
            [l, 0.0, 0.0],
            [0.0, l, 0.0],
            [0.0, 0.0, l],
            [l, 255.0 - l, 0.5 * l],
            [255.0, l, 17.0],
        ];
        for levels in cases {
            let back = s.intensity(s.counts(levels, &mut r));
            for c in 0..3 {
                let err = (back[c] - levels[c] / 255.0).abs();
                worst = worst.max(err);
                assert!(err < 0.01, "levels {levels:?} -> {back:?}");
            }
        }
    }
    eprintln!("worst round-trip error {worst}");
}

#[test]
fn crosstalk_shows_in_counts_and_is_undone() {
    let s = quiet();
    let mut r = rng::stream(1, 0, 0);
    let red = s.counts([255.0, 0.0, 0.0], &mut r);
    // Red light leaks into the green and blue channels.
    let dark = s.params().dark_counts;
    assert!(
        red[1] as f32 > dark + 100.0 && red[2] as f32 > dark + 100.0,
        "{red:?}"
    );
    let back = s.intensity(red);
    assert!(
        (back[0] - 1.0).abs() < 0.01 && back[1] < 0.01 && back[2] < 0.01,
        "{back:?}"
    );
}

#[test]
fn white_does_not_saturate_by_default_but_long_integration_does() {
    let s = quiet();
    let mut r = rng::stream(1, 0, 0);
    let white = s.counts([255.0; 3], &mut r);
    assert!(white.iter().all(|&c| c < 50_000), "{white:?}");
    let long = ColourSensor::new(ColourSensorParams {
        integration_ms: 50.0,
        noise: 0.0,
        ..ColourSensorParams::default()
    });
    let sat = long.counts([255.0; 3], &mut r);
    assert_eq!(sat, [65535; 3]);
    assert_eq!(long.intensity(sat), [1.0; 3]);
    // A saturated channel reads 1 whatever the others say.
    assert_eq!(s.intensity([65535, 0, 0])[0], 1.0);
    // Black reads the dark counts.
    assert_eq!(s.counts([0.0; 3], &mut r), [30; 3]);
    assert_eq!(s.intensity([30; 3]), [0.0; 3]);
    assert_eq!(s.intensity([0; 3]), [0.0; 3]);
}

#[test]
fn noise_has_the_configured_spread() {
    let s = ColourSensor::new(ColourSensorParams::default());
    let q = quiet();
    let mut r = rng::stream(9, 0, 0);
    let levels = [128.0, 64.0, 200.0];
    let mean_q = q.counts(levels, &mut r);
    let n = 20_000;
    let mut sum = [0.0f64; 3];
    let mut sum2 = [0.0f64; 3];
    for _ in 0..n {
        let c = s.counts(levels, &mut r);
        for k in 0..3 {
            sum[k] += c[k] as f64;
            sum2[k] += (c[k] as f64).powi(2);
        }
    }
    for k in 0..3 {
        let mean = sum[k] / n as f64;
        let sd = (sum2[k] / n as f64 - mean * mean).sqrt();
        // The noiseless count is rounded (up to 0.5 off the true mean); the mean of n draws of
        // sd 8 has a standard error of 8 / sqrt(n): four of them.
        assert!(
            (mean - mean_q[k] as f64).abs() < 0.5 + 4.0 * 8.0 / (n as f64).sqrt(),
            "channel {k} mean {mean} vs {}",
            mean_q[k]
        );
        // Rounding to integers adds 1/12 count^2 of variance.
        let expected = (64.0f64 + 1.0 / 12.0).sqrt();
        assert!((sd - expected).abs() < 0.2, "channel {k} sd {sd}");
    }
}

#[test]
fn inverse_matrix() {
    let m = ColourSensorParams::default().crosstalk;
    let inv = invert3(&m).unwrap();
    for (i, row) in m.iter().enumerate() {
        for j in 0..3 {
            let v: f32 = row
                .iter()
                .zip(&inv)
                .map(|(a, inv_row)| a * inv_row[j])
                .sum();
            assert!((v - if i == j { 1.0 } else { 0.0 }).abs() < 1e-6);
        }
    }
    assert!(invert3(&[[1.0, 2.0, 3.0], [2.0, 4.0, 6.0], [0.0, 0.0, 1.0]]).is_none());
}

fn uniform(colour: [f32; 3], value: f32) -> Pheromone {
    // A source so wide that it is flat over the arena: value at the centre = K / (2 pi sx sy).
    let sigma = 1000.0f32;
    let k = value * std::f32::consts::TAU * sigma * sigma;
    let source = GaussianSource {
        k,
        sigma_x: sigma,
        sigma_y: sigma,
        rho: 0.0,
        evaporation: f32::INFINITY,
        centre: Vec2::new(0.7, 0.4),
        start: 0.0,
    };
    Pheromone {
        name: "flat".into(),
        colour,
        model: FieldModel::Gaussian(GaussianField {
            sources: vec![source],
            time: 1.0,
        }),
    }
}

#[test]
fn screen_levels_of_a_flat_screen() {
    let s = quiet();
    let screen = ScreenSpec::default();
    let ph = [uniform([100.0, 200.0, 50.0], 1.0)];
    let levels = s.screen_levels(&ph, &screen, Vec2::new(0.5, 0.3));
    let expected =
        colcos_sim::screen::pixel_at(&ph, &screen, Vec2::new(0.5, 0.3)).map(|v| v as f32);
    assert_eq!(levels, expected);
    assert!(
        (levels[0] - 100.0).abs() <= 1.0 && (levels[1] - 200.0).abs() <= 1.0,
        "{levels:?}"
    );
    // And back through the sensor.
    let back = s.intensity(s.counts(levels, &mut rng::stream(1, 0, 0)));
    for c in 0..3 {
        assert!((back[c] - levels[c] / 255.0).abs() < 0.01);
    }
    // Blank screen: black.
    assert_eq!(s.screen_levels(&[], &screen, Vec2::new(0.5, 0.3)), [0.0; 3]);
}

#[test]
fn footprint_samples_lie_in_the_footprint() {
    let s = quiet();
    let p = Vec2::new(0.3, 0.2);
    let pts = s.sample_points(p);
    assert_eq!(pts[0], p);
    for q in &pts[1..] {
        let d = (*q - p).length();
        assert!((d - 0.7 * s.params().footprint_radius).abs() < 1e-6);
    }
}
