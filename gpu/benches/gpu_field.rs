//! GPU field benchmarks (plain timing, no criterion: one GPU step can take 100 ms on a software driver).
//!
//! `cargo bench -p colcos-gpu --bench gpu_field` runs:
//! 1. 4K (3840 x 2160), three pheromones, grid with diffusion (explicit and implicit), GPU and CPU:
//!    steps per second, effective memory traffic, ratio to the adapter's memory bandwidth
//!    (`COLCOS_GPU_BANDWIDTH_GBS`, or known for some adapters);
//! 2. 1,024 worlds of a trail task on 5 mm grids (one trail pheromone with evaporation and diffusion, four
//!    robots each laying a trail, sixteen colour sensors each): GPU batch against the CPU backend.
//!
//! `COLCOS_BENCH_STEPS` scales the number of steps (default 20 for 4K, 50 for the batch).
use colcos_gpu::screen::{GpuScreen, ScreenLayer, ScreenScene, SensorQuery};
use colcos_gpu::{AdapterPolicy, Deposit, GpuContext, GpuGrids};
use colcos_sim::Vec2;
use colcos_sim::field::{
    DiffusionScheme, FieldModel, GridField, GridParams, GridSpec, Kernel, Pheromone,
};
use colcos_sim::screen::ScreenSpec;
use colcos_sim::sensors::{ColourSensor, ColourSensorParams};
use rayon::prelude::*;
use std::time::Instant;

fn steps(default: usize) -> usize {
    std::env::var("COLCOS_BENCH_STEPS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(default)
}

/// Memory bandwidth of the adapter, GB/s, where known.
fn bandwidth(ctx: &GpuContext) -> Option<f64> {
    if let Some(b) = std::env::var("COLCOS_GPU_BANDWIDTH_GBS")
        .ok()
        .and_then(|s| s.parse().ok())
    {
        return Some(b);
    }
    let n = ctx.info.name.to_ascii_lowercase();
    [
        ("h200", 4800.0),
        ("h100", 3350.0),
        ("a100", 2039.0),
        ("l40s", 864.0),
        ("4090", 1008.0),
        ("3090", 936.0),
    ]
    .iter()
    .find(|(k, _)| n.contains(k))
    .map(|&(_, b)| b)
}

fn bench_4k(ctx: &std::sync::Arc<GpuContext>, d: f32, label: &str) {
    let screen = ScreenSpec::default();
    let spec = GridSpec::new(3840, 2160, screen.size[0] / 3840.0);
    let dt = 0.02;
    let params = GridParams {
        evaporation: 20.0,
        diffusion: d,
        scheme: DiffusionScheme::Auto,
        wind: Vec2::ZERO,
    };
    let r = d * dt / (spec.cell * spec.cell);
    let mut cpu: Vec<GridField> = (0..3).map(|_| GridField::new(spec, params)).collect();
    for (k, f) in cpu.iter_mut().enumerate() {
        for (i, v) in f.values_mut().iter_mut().enumerate() {
            *v = ((i * (k + 3)) % 1000) as f32 * 1e-3;
        }
    }
    // One batch of three fields where the adapter allows a 199 MB binding, else one batch per field
    // (lavapipe allows 128 MiB).
    let batches: Vec<GpuGrids> =
        match GpuGrids::from_fields(ctx.clone(), &cpu.iter().collect::<Vec<_>>()) {
            Ok(g) => vec![g],
            Err(_) => cpu
                .iter()
                .map(|f| GpuGrids::from_fields(ctx.clone(), &[f]).expect("4K field"))
                .collect(),
        };
    let mut gpu = batches;
    let nb = gpu.len();
    for _ in 0..2 {
        gpu.iter_mut().for_each(|g| g.step(dt).unwrap());
    }
    ctx.wait().unwrap();
    let n = steps(20);
    let t0 = Instant::now();
    for _ in 0..n {
        gpu.iter_mut().for_each(|g| g.step(dt).unwrap());
    }
    ctx.wait().unwrap();
    let gpu_s = t0.elapsed().as_secs_f64() / n as f64;
    let nc = steps(20).clamp(1, 10);
    let t0 = Instant::now();
    for _ in 0..nc {
        for f in cpu.iter_mut() {
            f.step(dt);
        }
    }
    let cpu_s = t0.elapsed().as_secs_f64() / nc as f64;
    // Minimum traffic of one step: every cell read once and written once per pass (explicit: 1 pass;
    // implicit: x-solve + y-solve, each read + write + the back-substitution's read + write).
    let passes = if r <= 0.25 { 1.0 } else { 2.0 };
    let bytes = 3.0 * spec.len() as f64 * 8.0 * passes;
    let gbs = bytes / gpu_s / 1e9;
    println!(
        "4K x 3 pheromones ({nb} batch(es)), {label} (d = {d:e} m^2/s, d dt/h^2 = {r:.3}): GPU {:.2} ms/step = {:.1} steps/s ({:.1}x real time at 20 ms), {gbs:.1} GB/s effective{}; CPU backend {:.1} ms/step = {:.1} steps/s; GPU/CPU {:.2}x",
        gpu_s * 1e3,
        1.0 / gpu_s,
        0.02 / gpu_s,
        bandwidth(ctx).map_or(
            " (adapter bandwidth unknown: set COLCOS_GPU_BANDWIDTH_GBS)".to_string(),
            |b| format!(" = {:.1} % of the adapter's {b} GB/s", 100.0 * gbs / b)
        ),
        cpu_s * 1e3,
        1.0 / cpu_s,
        cpu_s / gpu_s
    );
}

fn bench_batch(ctx: &std::sync::Arc<GpuContext>, worlds: usize) {
    let screen = ScreenSpec::default();
    let arena = Vec2::new(screen.size[0], screen.size[1]);
    let spec = GridSpec::covering(arena, 0.005);
    let dt = 0.02;
    let params = GridParams {
        evaporation: 20.0,
        diffusion: 2e-6,
        scheme: DiffusionScheme::Auto,
        wind: Vec2::ZERO,
    };
    let kernel = Kernel::Disc { radius: 0.008 };
    let robots = 4;
    let mut cpu: Vec<GridField> = (0..worlds).map(|_| GridField::new(spec, params)).collect();
    let refs: Vec<&GridField> = cpu.iter().collect();
    // A software adapter's binding limit (128 MiB on lavapipe) refuses 1,024 worlds in one batch.
    let mut gpu = match GpuGrids::from_fields(ctx.clone(), &refs) {
        Ok(g) => g,
        Err(e) => {
            println!("{worlds} worlds in one batch: {e}; no batch figure");
            return;
        }
    };
    let gs = match GpuScreen::new(ctx.clone()) {
        Ok(g) => g,
        Err(e) => {
            println!("screen pipelines: {e}; no batch figure");
            return;
        }
    };
    let sensor = ColourSensor::new(ColourSensorParams::default());
    // Robots drive in circles of different radii.
    let pos = |w: usize, r: usize, t: f32| -> Vec2 {
        let c = Vec2::new(0.3 + 0.25 * r as f32, 0.4);
        let rad = 0.1 + 0.0001 * w as f32;
        c + rad * Vec2::from_angle(t * 0.8 + w as f32 * 0.01 + r as f32)
    };
    let n = steps(50);
    let sensors_of = |w: usize, t: f32| -> Vec<Vec2> {
        (0..robots)
            .flat_map(|r| {
                (0..4).map(move |k| {
                    pos(w, r, t) + 0.015 * Vec2::from_angle(k as f32 * std::f32::consts::FRAC_PI_2)
                })
            })
            .collect()
    };
    // GPU: deposits, step, sensing, all in the batch; only the sensor sums come back.
    let scene = ScreenScene {
        worlds: (0..worlds)
            .map(|w| {
                vec![ScreenLayer::Grid {
                    colour: [255.0, 0.0, 0.0],
                    field: w,
                }]
            })
            .collect(),
    };
    let t0 = Instant::now();
    for s in 0..n {
        let t = s as f32 * dt;
        let deps: Vec<Deposit> = (0..worlds)
            .flat_map(|w| (0..robots).map(move |r| (w, r)))
            .map(|(w, r)| Deposit {
                field: w,
                kernel,
                a: pos(w, r, t - dt),
                b: pos(w, r, t),
                amount: 3.0 * dt,
            })
            .collect();
        gpu.deposit(&deps).unwrap();
        gpu.step(dt).unwrap();
        let queries: Vec<SensorQuery> = (0..worlds)
            .flat_map(|w| sensors_of(w, t).into_iter().map(move |c| (w, c)))
            .map(|(w, c)| SensorQuery {
                world: w as u32,
                points: sensor.sample_points(c),
            })
            .collect();
        let sums = gs.sense(Some(&gpu), &scene, &screen, &queries).unwrap();
        std::hint::black_box(sums);
    }
    let gpu_s = t0.elapsed().as_secs_f64() / n as f64;
    // CPU backend: the same work, worlds in parallel with rayon.
    let t0 = Instant::now();
    for s in 0..n {
        let t = s as f32 * dt;
        let fields = std::mem::take(&mut cpu);
        cpu = fields
            .into_par_iter()
            .enumerate()
            .map(|(w, mut f)| {
                for r in 0..robots {
                    f.deposit_segment(&kernel, pos(w, r, t - dt), pos(w, r, t), 3.0 * dt);
                }
                f.step(dt);
                let ph = [Pheromone {
                    name: "trail".into(),
                    colour: [255.0, 0.0, 0.0],
                    model: FieldModel::Grid(f),
                }];
                let mut acc = 0.0;
                for c in sensors_of(w, t) {
                    acc += sensor.screen_levels(&ph, &screen, c)[0];
                }
                std::hint::black_box(acc);
                let [p] = ph;
                match p.model {
                    FieldModel::Grid(g) => g,
                    _ => unreachable!(),
                }
            })
            .collect();
    }
    let cpu_s = t0.elapsed().as_secs_f64() / n as f64;
    println!(
        "{worlds} worlds x {}x{} grid (5 mm), {robots} robots laying trails, {} sensors each: GPU {:.2} ms/step ({:.0} world-steps/s), CPU backend ({} threads) {:.2} ms/step ({:.0} world-steps/s); GPU/CPU {:.2}x",
        spec.nx,
        spec.ny,
        robots * 4,
        gpu_s * 1e3,
        worlds as f64 / gpu_s,
        rayon::current_num_threads(),
        cpu_s * 1e3,
        worlds as f64 / cpu_s,
        cpu_s / gpu_s
    );
}

fn main() {
    // `cargo bench` passes --bench; `cargo test --benches` passes nothing useful: run only under bench.
    if !std::env::args().any(|a| a == "--bench") {
        return;
    }
    let ctx = match GpuContext::new(AdapterPolicy::Any) {
        Ok(c) => c,
        Err(e) => {
            println!("no GPU adapter, nothing to benchmark: {e}");
            return;
        }
    };
    println!("adapter: {}", ctx.describe());
    bench_4k(&ctx, 1e-6, "explicit");
    bench_4k(&ctx, 2e-6, "implicit");
    let worlds = std::env::var("COLCOS_BENCH_WORLDS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1024);
    bench_batch(&ctx, worlds);
}
