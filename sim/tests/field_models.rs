//! Gaussian model eq. (5), static maps, the screen eq. (1), and thread-count determinism.
use colcos_sim::Vec2;
use colcos_sim::channel::Channel;
use colcos_sim::field::{
    DiffusionScheme, FieldModel, GaussianField, GaussianSource, GridField, GridParams, GridSpec,
    Kernel, Pheromone, image_map, polyline_map,
};
use colcos_sim::screen::{ScreenSpec, pixel_at, render, save_png};
use colcos_testkit::threads::on_threads;

fn eq5(s: &GaussianSource, p: Vec2, t: f64) -> f64 {
    if t < s.start as f64 {
        return 0.0;
    }
    let (sx, sy, rho) = (s.sigma_x as f64, s.sigma_y as f64, s.rho as f64);
    let (dx, dy) = ((p.x - s.centre.x) as f64, (p.y - s.centre.y) as f64);
    let pi = std::f64::consts::PI;
    s.k as f64 / (2.0 * pi * sx * sy * (1.0 - rho * rho).sqrt())
        * (-(t - s.start as f64) / s.evaporation as f64).exp()
        * (-1.0 / (2.0 * (1.0 - rho * rho))
            * (dx * dx / (sx * sx) + dy * dy / (sy * sy) - 2.0 * rho * dx * dy / (sx * sy)))
            .exp()
}

#[test]
fn gaussian_source_matches_eq5() {
    for rho in [0.0f32, 0.6, -0.45] {
        let s = GaussianSource {
            k: 0.02,
            sigma_x: 0.05,
            sigma_y: 0.12,
            rho,
            evaporation: 7.0,
            centre: Vec2::new(0.7, 0.4),
            start: 2.0,
        };
        for t in [2.0f32, 2.5, 5.0, 20.0] {
            for p in [
                Vec2::new(0.7, 0.4),
                Vec2::new(0.75, 0.45),
                Vec2::new(0.62, 0.5),
                Vec2::new(0.9, 0.2),
            ] {
                let got = s.value_at(p, t) as f64;
                let want = eq5(&s, p, t as f64);
                assert!(
                    (got - want).abs() <= 1e-5 * want.abs() + 1e-30,
                    "rho {rho} t {t} p {p}: {got} vs {want}"
                );
            }
        }
        assert_eq!(s.value_at(s.centre, 1.9), 0.0);
    }
    // Peak value and the field's own clock.
    let s = GaussianSource {
        k: 1.0,
        sigma_x: 0.1,
        sigma_y: 0.1,
        rho: 0.0,
        evaporation: f32::INFINITY,
        centre: Vec2::ZERO,
        start: 0.0,
    };
    let peak = 1.0 / (2.0 * std::f32::consts::PI * 0.01);
    assert!((s.value_at(Vec2::ZERO, 100.0) / peak - 1.0).abs() < 1e-6);
    let mut g = GaussianField {
        sources: vec![s, s],
        time: 0.0,
    };
    g.step(0.5);
    assert!((g.value_at(Vec2::ZERO) / (2.0 * peak) - 1.0).abs() < 1e-6);
}

#[test]
fn polyline_map_has_the_given_width() {
    let spec = GridSpec::new(200, 100, 0.005);
    let pts = [
        Vec2::new(0.1, 0.25),
        Vec2::new(0.9, 0.25),
        Vec2::new(0.9, 0.05),
    ];
    let width = 0.04;
    let m = polyline_map(&spec, &pts, width, 3.0);
    // Column x = 0.5025 (i = 100) crosses the horizontal segment: cells within 0.02 of y = 0.25.
    let col: Vec<f32> = (0..spec.ny).map(|j| m[j * spec.nx + 100]).collect();
    let covered: Vec<usize> = (0..spec.ny).filter(|&j| col[j] > 0.0).collect();
    let ys: Vec<f32> = covered
        .iter()
        .map(|&j| (j as f32 + 0.5) * spec.cell)
        .collect();
    assert_eq!(covered.len(), 8, "{ys:?}");
    assert!(ys.iter().all(|&y| (y - 0.25).abs() <= 0.02));
    // Max, not sum, at the corner; 0 elsewhere.
    assert!(m.iter().all(|&v| v == 0.0 || v == 3.0));
    let corner = (50usize * spec.nx) + 179; // (0.8975, 0.2525)
    assert_eq!(m[corner], 3.0);
    assert_eq!(m[10 * spec.nx + 10], 0.0);
}

#[test]
fn image_map_reads_png_top_row_at_height() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("map.png");
    // 4 x 2 image: top row red 255, bottom row green 255, blue 102 everywhere.
    let mut img = image::RgbImage::new(4, 2);
    for (x, y, p) in img.enumerate_pixels_mut() {
        let _ = x;
        *p = if y == 0 {
            image::Rgb([255, 0, 102])
        } else {
            image::Rgb([0, 255, 102])
        };
    }
    img.save(&path).unwrap();
    let spec = GridSpec::new(8, 4, 0.1);
    let red = image_map(&spec, &path, Some(Channel::R), 2.0).unwrap();
    // Top grid row (j = 3) is the image's top row: full red; bottom row none.
    assert!((0..8).all(|i| (red[3 * 8 + i] - 2.0).abs() < 1e-6));
    assert!((0..8).all(|i| red[i].abs() < 1e-6));
    // Middle rows are interpolated.
    assert!(red[8] > 0.0 && red[8] < red[16] && red[16] < 2.0);
    let blue = image_map(&spec, &path, Some(Channel::B), 1.0).unwrap();
    assert!(blue.iter().all(|&v| (v - 0.4).abs() < 1e-6));
    let luma = image_map(&spec, &path, None, 255.0).unwrap();
    assert!((luma[3 * 8] - (0.299 * 255.0 + 0.114 * 102.0)).abs() < 1e-3);
    assert!(matches!(
        image_map(&spec, &dir.path().join("missing.png"), None, 1.0),
        Err(colcos_sim::error::SimError::Image { .. })
    ));
}

/// A grid pheromone `p` of `colour` on `spec`, its values set by `fill`.
fn grid_pheromone(
    colour: [f32; 3],
    spec: GridSpec,
    fill: impl FnOnce(&mut GridField),
) -> Pheromone {
    let mut g = GridField::new(spec, GridParams::default());
    fill(&mut g);
    Pheromone {
        name: "p".into(),
        colour,
        model: FieldModel::Grid(g),
    }
}

#[test]
fn pixel_at_rounds_and_clips() {
    let spec = GridSpec::new(4, 4, 0.25);
    // r 100.4 -> 100; b negative -> 0
    let a = grid_pheromone([100.0, 0.0, -50.0], spec, |g| g.values_mut().fill(1.004));
    // g rounds half away from zero -> 255
    let b = grid_pheromone([0.0, 1.0, 0.0], spec, |g| g.values_mut().fill(254.5));
    let screen = ScreenSpec::new([8, 8], [1.0, 1.0]);
    assert_eq!(
        pixel_at(&[a, b], &screen, Vec2::new(0.3, 0.6)),
        [100, 255, 0]
    );
    let c = grid_pheromone([3.0, 2.6, 0.0], spec, |g| g.values_mut().fill(1000.0));
    assert_eq!(pixel_at(&[c], &screen, Vec2::new(0.3, 0.6)), [255, 255, 0]);
    // Pixel centres.
    assert_eq!(screen.pixel_size(), Vec2::splat(0.125));
    assert_eq!(
        screen.pixel_centre(Vec2::new(0.3, 0.01)),
        Vec2::new(0.3125, 0.0625)
    );
    assert_eq!(
        screen.pixel_centre(Vec2::new(-1.0, 2.0)),
        Vec2::new(0.0625, 0.9375)
    );
}

#[test]
fn render_puts_high_y_at_the_top() {
    let spec = GridSpec::new(144, 81, 0.01);
    let p = grid_pheromone([0.0, 0.0, 255.0], spec, |g| {
        g.deposit_point(&Kernel::Disc { radius: 0.05 }, Vec2::new(0.3, 0.7), 1.0)
    });
    let gauss = Pheromone {
        name: "g".into(),
        colour: [255.0 * 0.01 * std::f32::consts::TAU, 0.0, 0.0],
        model: FieldModel::Gaussian(GaussianField {
            sources: vec![GaussianSource {
                k: 1.0,
                sigma_x: 0.1,
                sigma_y: 0.1,
                rho: 0.0,
                evaporation: f32::INFINITY,
                centre: Vec2::new(1.2, 0.1),
                start: 0.0,
            }],
            time: 0.0,
        }),
    };
    let screen = ScreenSpec::new([1440, 810], [1.44, 0.81]);
    let img = render(&[p, gauss], &screen, 144, 81);
    assert_eq!(img.dimensions(), (144, 81));
    // Blue blob at y = 0.7 m: image row (0.81 - 0.7) / 0.01 = 11 from the top, column 30.
    assert_eq!(img.get_pixel(30, 11).0[2], 255);
    assert_eq!(img.get_pixel(30, 81 - 1 - 11).0[2], 0);
    // Red Gaussian at y = 0.1 m: near the bottom rows, column 120.
    assert!(img.get_pixel(120, 71).0[0] > 200);
    assert_eq!(img.get_pixel(120, 5).0[0], 0);
    // Same values as pixel_at at the panel's own resolution.
    let full = render(
        std::slice::from_ref(&grid_pheromone([1.0; 3], spec, |_| {})),
        &screen,
        1440,
        810,
    );
    assert_eq!(full.dimensions(), (1440, 810));
    let dir = tempfile::tempdir().unwrap();
    save_png(&img, &dir.path().join("s.png")).unwrap();
}

#[test]
fn render_matches_pixel_at() {
    let spec = GridSpec::new(50, 30, 0.02);
    let p = grid_pheromone([40.0, 10.0, 0.0], spec, |g| {
        for (k, v) in g.values_mut().iter_mut().enumerate() {
            *v = (k % 13) as f32 * 0.37;
        }
    });
    let screen = ScreenSpec::new([160, 90], [1.0, 0.6]);
    let ps = [p];
    let img = render(&ps, &screen, 160, 90);
    for (x, row) in [(0u32, 0u32), (17, 33), (159, 89), (80, 45)] {
        let c = Vec2::new(
            (x as f32 + 0.5) * 1.0 / 160.0,
            0.6 - (row as f32 + 0.5) * 0.6 / 90.0,
        );
        assert_eq!(
            img.get_pixel(x, row).0,
            pixel_at(&ps, &screen, c),
            "{x},{row}"
        );
    }
}

#[test]
fn stepping_is_bit_identical_across_thread_counts() {
    let spec = GridSpec::new(3840, 2160, 1.439 / 3840.0);
    let h = spec.cell;
    let run = |threads: usize| -> Vec<Vec<f32>> {
        on_threads(threads, || {
            let cases = [
                (DiffusionScheme::Auto, 0.2 * h * h / 0.02, Vec2::ZERO, true),
                (
                    DiffusionScheme::Implicit,
                    3.0 * h * h / 0.02,
                    Vec2::new(0.01, -0.02),
                    false,
                ),
                (
                    DiffusionScheme::OneSided,
                    0.3 * h * h / 0.02,
                    Vec2::ZERO,
                    false,
                ),
            ];
            cases
                .iter()
                .map(|&(scheme, d, wind, inj)| {
                    let mut f = GridField::new(
                        spec,
                        GridParams {
                            evaporation: 8.0,
                            diffusion: d,
                            scheme,
                            wind,
                        },
                    );
                    f.deposit_segment(
                        &Kernel::Disc { radius: 0.01 },
                        Vec2::new(0.2, 0.2),
                        Vec2::new(1.2, 0.6),
                        3.0,
                    );
                    f.deposit_point(&Kernel::Cone { radius: 0.02 }, Vec2::new(1.43, 0.8), 5.0);
                    if inj {
                        let mut j = vec![0.0; spec.len()];
                        for k in (0..spec.len()).step_by(977) {
                            j[k] = 1.0;
                        }
                        f.set_static_injection(j);
                    }
                    for _ in 0..2 {
                        f.step(0.02);
                    }
                    f.values().to_vec()
                })
                .collect()
        })
    };
    let one = run(1);
    for n in [2, 4] {
        let other = run(n);
        for (a, b) in one.iter().zip(&other) {
            assert!(
                a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits()),
                "differs with {n} threads"
            );
        }
    }
}

/// Eq. (1) at one point the slow, obvious way: every field's own `value_at` at the pixel centre and
/// `f32::round` (the footprint path interpolates arrays of points and rounds without libm; it must
/// agree bit for bit).
fn reference_pixel(pheromones: &[Pheromone], screen: &ScreenSpec, p: Vec2) -> [u8; 3] {
    let c = screen.pixel_centre(p);
    let mut acc = [0f32; 3];
    for ph in pheromones {
        let v = ph.value_at(c);
        for (a, k) in acc.iter_mut().zip(ph.colour) {
            *a += k * v;
        }
    }
    acc.map(|a| a.round() as u8)
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(64))]
    /// Footprints of nine samples (the sensor's pattern, and wider ones spanning several cells) on
    /// coarse and fine grids with a Gaussian field among them, anywhere on the screen and past its
    /// edges, read the same levels as the per-point reference.
    #[test]
    fn footprint_pixels_match_per_point_reference(
        cell in proptest::sample::select(vec![0.0004f32, 0.003, 0.01, 0.2]),
        seed in 0u64..1_000,
        centre in (-0.05f32..1.05, -0.05f32..0.65),
        radius in proptest::sample::select(vec![0.0f32, 0.00105, 0.004, 0.03]),
    ) {
        use rand::{RngExt, SeedableRng};
        let mut rng = rand::rngs::SmallRng::seed_from_u64(seed);
        let spec = GridSpec::covering(Vec2::new(1.0, 0.6), cell);
        let mut ps: Vec<Pheromone> = [[255.0, 0.0, 0.0], [0.0, 255.0, 40.0], [10.0, 0.0, 255.0]]
            .into_iter()
            .map(|colour| {
                grid_pheromone(colour, spec, |g| {
                    g.values_mut().iter_mut().for_each(|v| *v = rng.random_range(0.0..1.2))
                })
            })
            .collect();
        ps.insert(1, Pheromone {
            name: "g".into(),
            colour: [60.0, 0.0, 90.0],
            model: FieldModel::Gaussian(GaussianField {
                sources: vec![GaussianSource {
                    k: 0.05, sigma_x: 0.1, sigma_y: 0.2, rho: 0.3, evaporation: 9.0,
                    centre: Vec2::new(0.4, 0.3), start: 0.0,
                }],
                time: 1.5,
            }),
        });
        let screen = ScreenSpec::new([2667, 1600], [1.0, 0.6]);
        let c = Vec2::new(centre.0, centre.1);
        let points: [Vec2; 9] = std::array::from_fn(|k| {
            if k == 0 { c } else { c + radius * Vec2::from_angle(k as f32 * std::f32::consts::FRAC_PI_4) }
        });
        let got = colcos_sim::screen::pixels_at(&ps, &screen, &points);
        for (p, g) in points.iter().zip(got) {
            proptest::prop_assert_eq!(g, reference_pixel(&ps, &screen, *p), "at {}", p);
        }
        // A robot's four footprints in one batch (groups of nine), on the processor's widest path and
        // on the portable one: the same levels as the per-point reference.
        let robot: [Vec2; 36] = std::array::from_fn(|k| {
            points[k % 9] + 0.015 * Vec2::from_angle((k / 9) as f32 * std::f32::consts::FRAC_PI_2)
        });
        let frozen = colcos_sim::field::FrozenSources::new(&ps);
        let fields = colcos_sim::screen::ScreenFields { pheromones: &ps, frozen: &frozen, screen: &screen };
        let fast = colcos_sim::screen::levels_at(&fields, &robot, 9);
        let portable = colcos_sim::screen::levels_at_portable(&fields, &robot, 9);
        proptest::prop_assert_eq!(fast, portable);
        for (k, p) in robot.iter().enumerate() {
            let want = reference_pixel(&ps, &screen, *p).map(u32::from);
            proptest::prop_assert_eq!([fast[0][k], fast[1][k], fast[2][k]], want, "at {}", p);
        }
    }
}

#[test]
fn levels_round_half_away_from_zero_and_clip() {
    use colcos_sim::screen::to_level;
    for x in [
        0.0f32, 0.49999997, 0.5, 1.5, 2.5, 254.49998, 254.5, 254.99, 255.0, 1e9, -0.4, -3.0,
    ] {
        assert_eq!(to_level(x), x.round().clamp(0.0, 255.0) as u8, "level {x}");
    }
    assert_eq!(to_level(f32::NAN), 0);
    assert_eq!(to_level(f32::INFINITY), 255);
    let mut x = 0.0f32;
    while x < 256.0 {
        assert_eq!(to_level(x), x.round().min(255.0) as u8, "level {x}");
        x += 0.013;
    }
}
