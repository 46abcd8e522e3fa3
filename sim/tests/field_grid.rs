//! Grid field, eq. (2): evaporation, injection, diffusion schemes, wind, deposits, interpolation.
use colcos_sim::Vec2;
use colcos_sim::field::{DiffusionScheme, GridField, GridParams, GridSpec, Kernel};

fn field(nx: usize, ny: usize, cell: f32, params: GridParams) -> GridField {
    GridField::new(GridSpec { nx, ny, cell }, params)
}

fn params(e: f32, d: f32, scheme: DiffusionScheme) -> GridParams {
    GridParams {
        evaporation: e,
        diffusion: d,
        scheme,
        wind: Vec2::ZERO,
    }
}

/// Centre of mass (m) and per-axis variance (m^2).
fn moments(f: &GridField) -> (Vec2, Vec2) {
    let s = *f.spec();
    let (mut m, mut mx, mut my) = (0f64, 0f64, 0f64);
    for j in 0..s.ny {
        for i in 0..s.nx {
            let v = f.values()[j * s.nx + i] as f64;
            let c = s.cell_centre(i, j);
            m += v;
            mx += v * c.x as f64;
            my += v * c.y as f64;
        }
    }
    let (cx, cy) = (mx / m, my / m);
    let (mut vx, mut vy) = (0f64, 0f64);
    for j in 0..s.ny {
        for i in 0..s.nx {
            let v = f.values()[j * s.nx + i] as f64;
            let c = s.cell_centre(i, j);
            vx += v * (c.x as f64 - cx).powi(2);
            vy += v * (c.y as f64 - cy).powi(2);
        }
    }
    (
        Vec2::new(cx as f32, cy as f32),
        Vec2::new((vx / m) as f32, (vy / m) as f32),
    )
}

fn blobs(f: &mut GridField) {
    let s = *f.spec();
    let size = s.size();
    let k = Kernel::Cone {
        radius: 0.12 * size.x.min(size.y),
    };
    f.deposit_point(&k, size * Vec2::new(0.3, 0.4), 5.0);
    f.deposit_point(&k, size * Vec2::new(0.05, 0.9), 2.0);
    f.deposit_segment(
        &Kernel::Disc {
            radius: 2.0 * s.cell,
        },
        size * 0.6,
        size * Vec2::new(0.97, 0.1),
        1.0,
    );
}

#[test]
fn pure_evaporation_matches_exp() {
    let mut f = field(40, 30, 0.01, params(10.0, 0.0, DiffusionScheme::Auto));
    for (k, v) in f.values_mut().iter_mut().enumerate() {
        *v = 1.0 + (k % 7) as f32;
    }
    let v0 = f.values().to_vec();
    let dt = 0.02;
    let steps = 3000;
    for _ in 0..steps {
        f.step(dt);
    }
    let expect = (-(steps as f64) * dt as f64 / 10.0).exp();
    for (v, v0) in f.values().iter().zip(&v0) {
        let rel = (*v as f64 / (*v0 as f64 * expect) - 1.0).abs();
        assert!(rel < 1e-5, "rel err {rel}");
    }
}

#[test]
fn steady_state_is_e_times_j() {
    for scheme in [DiffusionScheme::Auto, DiffusionScheme::Implicit] {
        let mut f = field(30, 20, 0.01, params(5.0, 0.0, scheme));
        let j: Vec<f32> = (0..600).map(|k| (k % 11) as f32 * 0.5).collect();
        f.set_static_injection(j.clone());
        for _ in 0..900 {
            f.step(0.1);
        }
        for (v, j) in f.values().iter().zip(&j) {
            assert!(
                (v - 5.0 * j).abs() <= 1e-5 * (5.0 * j).max(1.0),
                "{v} vs {}",
                5.0 * j
            );
        }
    }
}

#[test]
fn diffusion_conserves_mass_and_stays_positive() {
    let h = 0.01;
    // (scheme, d dt / h^2)
    for (scheme, r) in [
        (DiffusionScheme::Auto, 0.2),
        (DiffusionScheme::Auto, 3.0),
        (DiffusionScheme::Explicit, 0.2),
        (DiffusionScheme::Explicit, 2.7),
        (DiffusionScheme::Implicit, 0.2),
        (DiffusionScheme::Implicit, 5.0),
        (DiffusionScheme::OneSided, 0.3),
        (DiffusionScheme::OneSided, 2.0),
    ] {
        let dt = 0.02;
        let d = r * h * h / dt;
        let mut f = field(73, 41, h, params(f32::INFINITY, d, scheme));
        blobs(&mut f);
        let m0 = f.total_mass();
        for _ in 0..300 {
            f.step(dt);
        }
        let rel = (f.total_mass() / m0 - 1.0).abs();
        assert!(rel < 1e-4, "{scheme:?} r={r}: mass rel err {rel}");
        assert!(
            f.values().iter().all(|&v| v >= 0.0 && v.is_finite()),
            "{scheme:?} r={r}: negative"
        );
    }
}

#[test]
fn diffusion_conserves_mass_with_injection_fused() {
    // Auto explicit with a static map: mass grows by exactly sum(J) h^2 per second (e infinite).
    let h = 0.01;
    let mut f = field(
        50,
        30,
        h,
        params(f32::INFINITY, 0.2 * h * h / 0.02, DiffusionScheme::Auto),
    );
    let mut j = vec![0.0; 1500];
    j[15 * 50 + 20] = 100.0;
    j[29 * 50 + 49] = 50.0;
    f.set_static_injection(j);
    for _ in 0..200 {
        f.step(0.02);
    }
    let expect = 150.0 * 4.0 * (h as f64).powi(2);
    assert!(
        (f.total_mass() / expect - 1.0).abs() < 1e-4,
        "{} vs {expect}",
        f.total_mass()
    );
}

#[test]
fn huge_dt_is_bounded_and_positive() {
    for scheme in [DiffusionScheme::Implicit, DiffusionScheme::Auto] {
        let mut f = field(100, 60, 0.01, params(f32::INFINITY, 1.0, scheme));
        blobs(&mut f);
        let max0 = f.values().iter().cloned().fold(0.0, f32::max);
        let m0 = f.total_mass();
        for _ in 0..5 {
            f.step(100.0);
        }
        let v = f.values();
        assert!(
            v.iter().all(|&v| v >= 0.0 && v.is_finite() && v <= max0),
            "{scheme:?}"
        );
        let mean = v.iter().map(|&v| v as f64).sum::<f64>() / v.len() as f64;
        assert!(
            v.iter().all(|&v| ((v as f64) - mean).abs() < 1e-3 * mean),
            "{scheme:?}: not uniform"
        );
        assert!((f.total_mass() / m0 - 1.0).abs() < 1e-4);
    }
}

#[test]
fn point_mass_spreads_as_analytic_gaussian() {
    // Variance per axis grows as 2 d t.
    for (scheme, d, dt) in [
        (DiffusionScheme::Auto, 1e-5f32, 0.02f32),
        (DiffusionScheme::Explicit, 1e-4, 0.1),
        (DiffusionScheme::Implicit, 1e-4, 0.1),
    ] {
        let mut f = field(201, 201, 0.005, params(f32::INFINITY, d, scheme));
        f.values_mut()[100 * 201 + 100] = 1.0;
        let t = if d < 5e-5 { 20.0 } else { 10.0 };
        let steps = (t / dt).round() as usize;
        for _ in 0..steps {
            f.step(dt);
        }
        let (c, var) = moments(&f);
        let expect = 2.0 * d * t;
        for v in [var.x, var.y] {
            assert!(
                (v / expect - 1.0).abs() < 0.03,
                "{scheme:?}: var {v} vs {expect}"
            );
        }
        assert!((c - Vec2::splat(100.5 * 0.005)).abs().max_element() < 1e-5);
        // The profile along x through the centre follows exp(-x^2 / (4 d t)).
        let peak = f.values()[100 * 201 + 100];
        let at = f.values()[100 * 201 + 110];
        let x = 10.0 * 0.005;
        let ratio = at / peak;
        let expect_ratio = (-x * x / (4.0 * d * t)).exp();
        assert!(
            (ratio / expect_ratio - 1.0).abs() < 0.05,
            "{scheme:?}: {ratio} vs {expect_ratio}"
        );
    }
}

#[test]
fn one_sided_drifts_toward_plus_x_plus_y_symmetric_does_not() {
    let h = 0.01;
    let run = |scheme| {
        let mut f = field(60, 60, h, params(f32::INFINITY, 0.2 * h * h / 0.02, scheme));
        f.deposit_point(&Kernel::Disc { radius: 0.05 }, Vec2::new(0.3, 0.3), 1.0);
        let (c0, _) = moments(&f);
        for _ in 0..100 {
            f.step(0.02);
        }
        let (c, _) = moments(&f);
        c - c0
    };
    let sym = run(DiffusionScheme::Auto);
    assert!(sym.abs().max_element() < 1e-5, "symmetric moved {sym}");
    let one = run(DiffusionScheme::OneSided);
    // Upwind transport at d / (2h) per axis: 100 steps * 0.1 cell.
    assert!(one.x > 5.0 * h && one.y > 5.0 * h, "one-sided moved {one}");
    assert!(
        (one.x - 10.0 * h).abs() < 0.5 * h && (one.y - 10.0 * h).abs() < 0.5 * h,
        "{one}"
    );
}

#[test]
fn wind_moves_centre_of_mass_and_conserves_mass() {
    let h = 0.005;
    for wind in [Vec2::new(0.05, -0.03), Vec2::new(-0.2, 0.11)] {
        let mut f = field(
            200,
            200,
            h,
            GridParams {
                evaporation: f32::INFINITY,
                diffusion: 0.0,
                scheme: DiffusionScheme::Auto,
                wind,
            },
        );
        f.deposit_point(&Kernel::Cone { radius: 0.05 }, Vec2::new(0.5, 0.5), 1.0);
        let (c0, _) = moments(&f);
        let m0 = f.total_mass();
        let t = 1.0;
        for _ in 0..50 {
            f.step(0.02);
        }
        let (c, _) = moments(&f);
        let moved = c - c0;
        assert!(
            (moved - wind * t).abs().max_element() < h,
            "moved {moved} vs {}",
            wind * t
        );
        assert!((f.total_mass() / m0 - 1.0).abs() < 1e-5);
        assert!(f.values().iter().all(|&v| v >= 0.0));
    }
}

#[test]
fn deposit_segment_leaves_no_gaps() {
    let h = 0.001;
    let mut f = field(500, 300, h, GridParams::default());
    let (a, b) = (Vec2::new(0.05, 0.05), Vec2::new(0.4, 0.23));
    let r = 0.003;
    f.deposit_segment(&Kernel::Disc { radius: r }, a, b, 2.5);
    let s = *f.spec();
    let ab = b - a;
    let mut on = 0;
    for j in 0..s.ny {
        for i in 0..s.nx {
            let p = s.cell_centre(i, j);
            let t = ((p - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0);
            let dist = (p - (a + ab * t)).length();
            let v = f.values()[j * s.nx + i];
            if dist <= r * 0.999 {
                assert_eq!(v, 2.5, "gap at {i},{j}");
                on += 1;
            } else if dist > r * 1.001 {
                assert_eq!(v, 0.0, "spill at {i},{j}");
            }
        }
    }
    assert!(on > 2000);
    // Point deposit with a cone: centre cell gets the full amount.
    let mut g = field(11, 11, 0.01, GridParams::default());
    g.deposit_point(&Kernel::Cone { radius: 0.02 }, Vec2::new(0.055, 0.055), 1.0);
    assert_eq!(g.values()[5 * 11 + 5], 1.0);
    assert!((g.values()[5 * 11 + 6] - 0.5).abs() < 1e-5);
}

#[test]
fn value_at_is_bilinear_and_clamped() {
    let mut f = field(10, 8, 0.1, GridParams::default());
    let s = *f.spec();
    for j in 0..s.ny {
        for i in 0..s.nx {
            let c = s.cell_centre(i, j);
            f.values_mut()[j * s.nx + i] = 2.0 * c.x + 3.0 * c.y;
        }
    }
    let lin = |p: Vec2| 2.0 * p.x + 3.0 * p.y;
    for p in [
        Vec2::new(0.33, 0.41),
        Vec2::new(0.05, 0.05),
        Vec2::new(0.95, 0.75),
        Vec2::new(0.5, 0.2),
    ] {
        assert!((f.value_at(p) - lin(p)).abs() < 1e-5, "{p}");
    }
    // Clamped beyond the outer cell centres and outside the arena.
    assert!((f.value_at(Vec2::new(0.0, 0.0)) - lin(Vec2::new(0.05, 0.05))).abs() < 1e-5);
    assert!((f.value_at(Vec2::new(5.0, -3.0)) - lin(Vec2::new(0.95, 0.05))).abs() < 1e-5);
    assert!(
        (f.total_mass() - f.values().iter().map(|&v| v as f64).sum::<f64>() * 0.01).abs() < 1e-6
    );
}
