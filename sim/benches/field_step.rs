//! One 20 ms step of three pheromone grid fields, against the memory floor.
//!
//! ```text
//! cargo bench -p colcos-sim --bench field_step
//! ```
//!
//! Cases: (a) 3840x2160x3, Auto (one fused explicit pass, d dt / h^2 = 0.14); (b) the same with the
//! implicit scheme; (c) the memory floor: one read pass and one write pass over 3 x 3840x2160 f32, in
//! place, parallel on all cores; (d) 640x480x3, Auto. After criterion, a plain summary: median ms per
//! case, ratio to the memory floor and to real time (20 ms).
use colcos_sim::Vec2;
use colcos_sim::field::{DiffusionScheme, GridField, GridParams, GridSpec, Kernel};
use criterion::Criterion;
use rayon::prelude::*;
use std::hint::black_box;
use std::time::{Duration, Instant};

const DT: f32 = 0.02;
const D: f32 = 1e-6;
const WIDTH: f32 = 1.439;

fn fields(nx: usize, ny: usize, scheme: DiffusionScheme) -> Vec<GridField> {
    let spec = GridSpec::new(nx, ny, WIDTH / nx as f32);
    [8.0f32, 200.0, 300.0]
        .iter()
        .map(|&e| {
            let mut f = GridField::new(
                spec,
                GridParams {
                    evaporation: e,
                    diffusion: D,
                    scheme,
                    wind: Vec2::ZERO,
                },
            );
            f.deposit_segment(
                &Kernel::Cone { radius: 0.05 },
                Vec2::new(0.2, 0.2),
                Vec2::new(1.2, 0.6),
                200.0,
            );
            f
        })
        .collect()
}

fn step_all(fs: &mut [GridField]) {
    for f in fs.iter_mut() {
        f.step(DT);
    }
}

/// One read pass and one write pass (in place) over the arrays, parallel.
fn floor_pass(arrays: &mut [Vec<f32>]) {
    for a in arrays.iter_mut() {
        a.par_chunks_mut(1 << 16)
            .for_each(|c| c.iter_mut().for_each(|v| *v *= 0.999_9));
    }
}

fn floor_arrays() -> Vec<Vec<f32>> {
    (0..3).map(|k| vec![1.0 + k as f32; 3840 * 2160]).collect()
}

struct Case {
    name: &'static str,
    run: Box<dyn FnMut()>,
}

/// A case that runs `f` on its own `state`.
fn case<T, U>(name: &'static str, mut state: T, f: fn(&mut U)) -> Case
where
    T: AsMut<U> + 'static,
    U: ?Sized + 'static,
{
    Case {
        name,
        run: Box::new(move || f(black_box(&mut state).as_mut())),
    }
}

fn cases() -> Vec<Case> {
    use DiffusionScheme::{Auto, Implicit};
    vec![
        case("4k_x3_auto_explicit", fields(3840, 2160, Auto), step_all),
        case("4k_x3_implicit", fields(3840, 2160, Implicit), step_all),
        case("memory_floor_4k_x3", floor_arrays(), floor_pass),
        case("640x480_x3_auto", fields(640, 480, Auto), step_all),
    ]
}

fn median_ms(run: &mut dyn FnMut(), n: usize) -> f64 {
    run();
    let mut t: Vec<f64> = (0..n)
        .map(|_| {
            let t0 = Instant::now();
            run();
            t0.elapsed().as_secs_f64() * 1e3
        })
        .collect();
    t.sort_by(|a, b| a.total_cmp(b));
    t[n / 2]
}

fn main() {
    let mut crit = Criterion::default()
        .sample_size(10)
        .warm_up_time(Duration::from_millis(300))
        .measurement_time(Duration::from_secs(2))
        .configure_from_args();
    let mut cs = cases();
    {
        let mut g = crit.benchmark_group("field_step");
        for c in cs.iter_mut() {
            g.bench_function(c.name, |bch| bch.iter(|| (c.run)()));
        }
        g.finish();
    }
    crit.final_summary();

    // Plain summary: medians of 21 runs, interleaved case by case.
    let threads = rayon::current_num_threads();
    let medians: Vec<(String, f64)> = cs
        .iter_mut()
        .map(|c| (c.name.to_string(), median_ms(&mut *c.run, 21)))
        .collect();
    let floor = medians
        .iter()
        .find(|(n, _)| n.starts_with("memory_floor"))
        .map(|m| m.1)
        .unwrap_or(f64::NAN);
    println!("\nfield_step summary ({threads} rayon threads, dt = 20 ms, d = {D} m^2/s):");
    for (name, ms) in &medians {
        let floor_ratio = if name.starts_with("640") {
            // The floor scales with the number of cells.
            ms / (floor * (640.0 * 480.0) / (3840.0 * 2160.0))
        } else {
            ms / floor
        };
        println!(
            "  {name:<22} median {ms:8.2} ms   x{floor_ratio:5.2} memory floor   {:6.3} of real time (20 ms)",
            ms / 20.0
        );
    }
}
