//! The screen renderer (`render`, `render_into`, `ScreenRenderer`) gives, byte for byte, the image of
//! the straightforward per-pixel evaluation of eq. (1) (`colcos_testkit::screen::reference_render`), for grid and
//! Gaussian fields, random values, sizes and colour maps.
use colcos_sim::Vec2;
use colcos_sim::field::{
    FieldModel, GaussianField, GaussianSource, GridField, GridParams, GridSpec, Pheromone,
};
use colcos_sim::screen::{Instructions, ScreenRenderer, ScreenSpec, render, render_into, to_level};
use colcos_testkit::screen::reference_render;
use rand::rngs::SmallRng;
use rand::{RngExt, SeedableRng};

fn grid(spec: GridSpec, colour: [f32; 3], mut value: impl FnMut(usize) -> f32) -> Pheromone {
    let mut g = GridField::new(spec, GridParams::default());
    g.values_mut()
        .iter_mut()
        .enumerate()
        .for_each(|(k, v)| *v = value(k));
    Pheromone {
        name: "grid".into(),
        colour,
        model: FieldModel::Grid(g),
    }
}

/// A grid of `cells` (nx, ny) of `cell` m and a screen of `resolution` pixels showing `size` m.
fn grid_and_screen(
    cells: [usize; 2],
    cell: f32,
    resolution: [u32; 2],
    size: [f32; 2],
) -> (GridSpec, ScreenSpec) {
    let [nx, ny] = cells;
    (GridSpec { nx, ny, cell }, ScreenSpec { resolution, size })
}

fn random_colour(rng: &mut SmallRng) -> [f32; 3] {
    std::array::from_fn(|_| match rng.random_range(0..5) {
        0 | 1 => 0.0,
        2 => 255.0,
        3 => rng.random_range(-300.0..300.0),
        _ => rng.random_range(0.0..2000.0),
    })
}

fn random_gaussian(rng: &mut SmallRng, size: [f32; 2]) -> Pheromone {
    let sources = (0..rng.random_range(0..4))
        .map(|_| GaussianSource {
            k: rng.random_range(-0.02..0.05),
            sigma_x: rng.random_range(0.005..0.3),
            sigma_y: rng.random_range(0.005..0.3),
            rho: rng.random_range(-0.8..0.8),
            evaporation: if rng.random_bool(0.3) {
                f32::INFINITY
            } else {
                rng.random_range(0.5..20.0)
            },
            centre: Vec2::new(
                rng.random_range(-0.1..size[0] + 0.1),
                rng.random_range(-0.1..size[1] + 0.1),
            ),
            start: rng.random_range(0.0..3.0),
        })
        .collect();
    Pheromone {
        name: "gauss".into(),
        colour: random_colour(rng),
        model: FieldModel::Gaussian(GaussianField {
            sources,
            time: rng.random_range(0.0..4.0),
        }),
    }
}

/// A random world: 1 to 4 pheromones on one or two grid geometries (fine or coarser than the pixels,
/// covering the panel or not), values smooth, noisy or spiky, and Gaussian fields among them.
fn random_world(rng: &mut SmallRng) -> (Vec<Pheromone>, ScreenSpec, u32, u32) {
    let size = [rng.random_range(0.05..1.6), rng.random_range(0.05..1.0)];
    let (w, h) = (rng.random_range(1..260), rng.random_range(1..160));
    let spec = |rng: &mut SmallRng| {
        let cell = rng.random_range(0.001..0.12f32);
        let cover = rng.random_range(0.7..1.3f32);
        GridSpec::new(
            ((size[0] * cover / cell) as usize).clamp(1, 400),
            ((size[1] * cover / cell) as usize).clamp(1, 400),
            cell,
        )
    };
    let specs = [spec(rng), spec(rng)];
    let pheromones = (0..rng.random_range(1..5))
        .map(|_| {
            if rng.random_bool(0.25) {
                return random_gaussian(rng, size);
            }
            let s = specs[rng.random_range(0..2)];
            let colour = random_colour(rng);
            let kind = rng.random_range(0..3);
            let scale = rng.random_range(0.01..3.0f32);
            let mut r = SmallRng::seed_from_u64(rng.random());
            grid(s, colour, |k| match kind {
                0 => scale * ((k % s.nx) as f32 * 0.3).sin().abs(),
                1 => r.random_range(-0.2..scale),
                _ if r.random_bool(0.05) => r.random_range(0.0..50.0),
                _ => 0.0,
            })
        })
        .collect();
    let screen = ScreenSpec::new([w, h], size);
    (pheromones, screen, w, h)
}

/// Every instruction set the renderer has gives the reference's bytes (`render` takes the best).
fn assert_same(pheromones: &[Pheromone], screen: &ScreenSpec, w: u32, h: u32, what: &str) {
    let want = reference_render(pheromones, screen, w as usize, h as usize);
    let got = render(pheromones, screen, w, h);
    assert_eq!(got.dimensions(), (w, h));
    check(&want, got.as_raw(), w, h, &format!("{what}, render"));
    for isa in [Instructions::Avx2, Instructions::Portable] {
        let got = ScreenRenderer::with_instructions(isa).render(pheromones, screen, w, h);
        check(&want, got.as_raw(), w, h, &format!("{what}, {isa:?}"));
    }
}

fn check(want: &[u8], got: &[u8], w: u32, h: u32, what: &str) {
    if let Some(k) = want.iter().zip(got).position(|(a, b)| a != b) {
        let (px, row) = ((k / 3) % w as usize, k / 3 / w as usize);
        panic!(
            "{what}: {w}x{h}, pixel ({px}, {row}) channel {}: {} want {}",
            k % 3,
            got[k],
            want[k]
        );
    }
}

#[test]
fn random_worlds_render_as_the_reference_render() {
    let mut rng = SmallRng::seed_from_u64(0x5c4ee);
    for case in 0..300 {
        let (pheromones, screen, w, h) = random_world(&mut rng);
        assert_same(&pheromones, &screen, w, h, &format!("case {case}"));
    }
}

/// Large images (the parallel path), at the panel's 4K with three 5 mm grids and at sizes that do not
/// fill whole blocks of pixels, with a Gaussian field among the grids.
#[test]
fn large_images_render_as_the_reference_render() {
    let screen = ScreenSpec::default();
    let spec = GridSpec::covering(Vec2::new(screen.size[0], screen.size[1]), 0.005);
    let mut rng = SmallRng::seed_from_u64(7);
    let mut ps: Vec<Pheromone> = [[255.0, 0.0, 0.0], [0.0, 255.0, 0.0], [0.0, 0.0, 255.0]]
        .into_iter()
        .map(|c| grid(spec, c, |_| rng.random_range(0.0..1.3)))
        .collect();
    assert_same(&ps, &screen, 3840, 2160, "three grids at 4K");
    ps.push(random_gaussian(&mut rng, screen.size));
    assert_same(&ps, &screen, 1001, 563, "grids and a Gaussian field");
}

/// Values no scenario makes (NaN, infinities, huge) still give the reference's bytes.
#[test]
fn non_finite_values_render_as_the_reference_render() {
    let (spec, screen) = grid_and_screen([13, 7], 0.05, [97, 61], [0.6, 0.4]);
    let specials = [f32::NAN, f32::INFINITY, -f32::INFINITY, f32::MAX, -f32::MAX];
    for (k, &special) in specials.iter().enumerate() {
        let ps = [
            grid(spec, [255.0, 0.0, 30.0], |i| {
                if i % 11 == k { special } else { 0.5 }
            }),
            grid(spec, [0.0, 100.0, 0.0], |i| (i % 5) as f32 * 0.3),
        ];
        assert_same(&ps, &screen, 97, 61, &format!("{special}"));
    }
}

/// Levels on the edges of eq. (1)'s rounding (half away from zero) and clipping come out as
/// `to_level` gives them, in every instruction set.
#[test]
fn rounding_edges_give_to_level() {
    let (spec, screen) = grid_and_screen([4, 3], 0.1, [37, 5], [0.4, 0.3]);
    let below_half = f32::from_bits(0.5f32.to_bits() - 1);
    let edges = [
        0.0,
        -0.0,
        below_half,
        0.5,
        1.5,
        2.5,
        127.49999,
        127.5,
        254.5,
        254.49998,
        255.0,
        255.5,
        256.0,
        3e9,
        -0.5,
        -0.7,
        -3e9,
        f32::NAN,
        f32::INFINITY,
        -f32::INFINITY,
    ];
    for v in edges {
        let ps = [
            grid(spec, [1.0, 1.0, 0.0], |_| v),
            grid(spec, [0.0, 0.0, 1.0], |_| v),
        ];
        assert_same(&ps, &screen, 37, 5, &format!("level {v}"));
        if v.is_finite() {
            // (Between two infinite cells the interpolation is NaN, as in `value_at`.)
            let img = render(&ps, &screen, 37, 5);
            assert!(img.pixels().all(|p| p.0 == [to_level(v); 3]), "level {v}");
        }
    }
}

/// `render_into` and a kept `ScreenRenderer` reuse their tables across frames and sizes and still
/// draw each frame as `render` does.
#[test]
fn kept_renderers_follow_changing_fields_and_sizes() {
    let (spec, screen) = grid_and_screen([30, 20], 0.04, [300, 200], [1.2, 0.8]);
    let mut renderer = ScreenRenderer::new();
    let mut rng = SmallRng::seed_from_u64(3);
    for (frame, (w, h)) in [(300, 200), (300, 200), (77, 41), (300, 200)]
        .into_iter()
        .enumerate()
    {
        let ps = [
            grid(spec, [200.0, 10.0, 0.0], |_| rng.random_range(0.0..1.5)),
            random_gaussian(&mut rng, screen.size),
        ];
        let want = reference_render(&ps, &screen, w, h);
        let mut img = image::RgbImage::new(w as u32, h as u32);
        renderer.render_into(&ps, &screen, &mut img);
        assert_eq!(img.as_raw(), &want, "kept renderer, frame {frame}");
        let mut img = image::RgbImage::from_pixel(w as u32, h as u32, image::Rgb([9, 9, 9]));
        render_into(&ps, &screen, &mut img);
        assert_eq!(img.as_raw(), &want, "render_into, frame {frame}");
    }
}

#[test]
fn empty_images_and_worlds() {
    let screen = ScreenSpec::default();
    assert_eq!(render(&[], &screen, 0, 5).dimensions(), (0, 5));
    let img = render(&[], &screen, 4, 3);
    assert!(img.as_raw().iter().all(|&b| b == 0));
    let empty = grid(GridSpec::new(0, 0, 0.1), [255.0; 3], |_| 1.0);
    let img = render(&[empty], &screen, 8, 8);
    assert!(img.as_raw().iter().all(|&b| b == 0), "an empty grid is 0");
}
