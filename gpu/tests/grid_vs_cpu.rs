//! The GPU grid backend against the CPU one: every scheme and option, hundreds of steps, 1e-5 relative.
mod common;
use colcos_gpu::{Deposit, GpuContext, GpuGrids};
use colcos_sim::Vec2;
use colcos_sim::field::{DiffusionScheme, GridField, GridParams, GridSpec, Kernel};
use common::{Lcg, compare, ctx};
use std::sync::Arc;

const TOL: f64 = 1e-5;

fn random_field(spec: GridSpec, params: GridParams, seed: u64, with_injection: bool) -> GridField {
    let mut f = GridField::new(spec, params);
    let mut rng = Lcg(seed);
    // A smooth part plus spikes, so that diffusion and wind have something to move.
    for j in 0..spec.ny {
        for i in 0..spec.nx {
            let spike = if rng.next() < 0.02 {
                5.0 * rng.next()
            } else {
                0.0
            };
            f.values_mut()[j * spec.nx + i] = (i as f32 * 0.1).sin().abs() + spike;
        }
    }
    if with_injection {
        let j: Vec<f32> = (0..spec.len())
            .map(|_| if rng.next() < 0.1 { rng.next() } else { 0.0 })
            .collect();
        f.set_static_injection(j);
    }
    f
}

/// Each case as a random CPU field (seeds from `seed`) and the same fields as one GPU batch.
fn batch(
    ctx: Arc<GpuContext>,
    spec: GridSpec,
    cases: &[(GridParams, bool)],
    seed: u64,
) -> (Vec<GridField>, GpuGrids) {
    let cpu: Vec<GridField> = cases
        .iter()
        .enumerate()
        .map(|(k, &(p, inj))| random_field(spec, p, seed + k as u64, inj))
        .collect();
    let refs: Vec<&GridField> = cpu.iter().collect();
    let gpu = GpuGrids::from_fields(ctx, &refs).expect("gpu grids");
    (cpu, gpu)
}

/// Steps `cases` on the CPU and, together in one batch, on the GPU; checks every `check` steps.
fn run_cases(
    name: &str,
    spec: GridSpec,
    cases: &[(GridParams, bool)],
    dt: f32,
    steps: usize,
    deposits: bool,
) {
    let Some(ctx) = ctx() else { return };
    let (mut cpu, mut gpu) = batch(ctx, spec, cases, 7);
    let mut rng = Lcg(99);
    let kernels = [
        Kernel::Disc { radius: 0.012 },
        Kernel::Cone { radius: 0.02 },
        Kernel::Gaussian { sigma: 0.006 },
    ];
    let size = spec.size();
    let mut pos: Vec<Vec2> = (0..cases.len() * 2)
        .map(|_| Vec2::new(rng.next() * size.x, rng.next() * size.y))
        .collect();
    let mut bit_same = 0usize;
    for step in 1..=steps {
        if deposits {
            let mut deps = Vec::new();
            for (k, p) in pos.iter_mut().enumerate() {
                let field = k % cases.len();
                let to = (*p + Vec2::new(rng.next() - 0.5, rng.next() - 0.5) * 0.03)
                    .clamp(Vec2::ZERO, size);
                let d = Deposit {
                    field,
                    kernel: kernels[k % 3],
                    a: *p,
                    b: to,
                    amount: 0.05,
                };
                cpu[field].deposit_segment(&d.kernel, d.a, d.b, d.amount);
                deps.push(d);
                *p = to;
            }
            gpu.deposit(&deps).unwrap();
        }
        for f in cpu.iter_mut() {
            f.step(dt);
        }
        gpu.step(dt).unwrap();
        if step % 50 == 0 || step == steps {
            let all = gpu.read_all().unwrap();
            for (k, (g, c)) in all.iter().zip(&cpu).enumerate() {
                let (err, same) = compare(g, c.values());
                bit_same = same;
                assert!(
                    err <= TOL,
                    "{name}, case {k} ({:?}), step {step}: relative error {err:e}",
                    cases[k].0
                );
            }
        }
    }
    eprintln!(
        "{name}: {steps} steps within {TOL:e}; bit-identical cells in the last field: {bit_same} of {}",
        spec.len()
    );
}

fn spec() -> GridSpec {
    GridSpec::new(97, 61, 0.005)
}

fn p(e: f32, d: f32, scheme: DiffusionScheme, wind: [f32; 2]) -> GridParams {
    GridParams {
        evaporation: e,
        diffusion: d,
        scheme,
        wind: Vec2::from(wind),
    }
}

#[test]
fn evaporation_and_static_injection() {
    use DiffusionScheme::*;
    let cases = [
        (p(10.0, 0.0, Auto, [0.0, 0.0]), false),
        (p(10.0, 0.0, Auto, [0.0, 0.0]), true),
        (p(f32::INFINITY, 0.0, Auto, [0.0, 0.0]), true),
        (p(0.5, 0.0, Implicit, [0.0, 0.0]), true),
        (p(0.0, 0.0, Auto, [0.0, 0.0]), true),
    ];
    run_cases("evaporation", spec(), &cases, 0.02, 300, false);
}

#[test]
fn explicit_diffusion() {
    use DiffusionScheme::*;
    // d dt / h^2 = 0.16 (fused single pass) and 1.6 (Explicit: 7 sub-steps).
    let cases = [
        (p(20.0, 2e-4, Auto, [0.0, 0.0]), false),
        (p(20.0, 2e-4, Auto, [0.0, 0.0]), true),
        (p(f32::INFINITY, 2e-3, Explicit, [0.0, 0.0]), true),
        (p(5.0, 2e-3, Explicit, [0.0, 0.0]), false),
    ];
    run_cases("explicit", spec(), &cases, 0.02, 300, false);
}

#[test]
fn implicit_diffusion() {
    use DiffusionScheme::*;
    // d dt / h^2 = 1.6 (Auto goes implicit) and 16.
    let cases = [
        (p(20.0, 2e-3, Auto, [0.0, 0.0]), true),
        (p(20.0, 2e-2, Implicit, [0.0, 0.0]), false),
        (p(f32::INFINITY, 2e-4, Implicit, [0.0, 0.0]), true),
    ];
    run_cases("implicit", spec(), &cases, 0.02, 300, false);
}

#[test]
fn one_sided_diffusion() {
    use DiffusionScheme::*;
    let cases = [
        (p(20.0, 2e-4, OneSided, [0.0, 0.0]), true),
        (p(f32::INFINITY, 4e-3, OneSided, [0.0, 0.0]), false),
    ];
    run_cases("one-sided", spec(), &cases, 0.02, 300, false);
}

#[test]
fn wind() {
    use DiffusionScheme::*;
    // Courant numbers per step up to 2 (4 sub-steps), both signs, with each diffusion scheme.
    let cases = [
        (p(20.0, 0.0, Auto, [0.1, 0.0]), false),
        (p(20.0, 2e-4, Auto, [-0.2, 0.05]), true),
        (p(20.0, 2e-3, Implicit, [0.3, -0.5]), true),
        (p(f32::INFINITY, 2e-4, OneSided, [0.0, -0.1]), false),
        (p(20.0, 2e-3, Explicit, [0.05, 0.05]), false),
    ];
    run_cases("wind", spec(), &cases, 0.02, 300, false);
}

#[test]
fn trail_deposits_along_segments() {
    use DiffusionScheme::*;
    let cases = [
        (p(20.0, 2e-6, Auto, [0.0, 0.0]), false),
        (p(20.0, 2e-3, Auto, [0.0, 0.0]), true),
        (p(30.0, 0.0, Auto, [0.02, 0.0]), false),
    ];
    run_cases("deposits", spec(), &cases, 0.02, 200, true);
}

#[test]
fn odd_shapes() {
    use DiffusionScheme::*;
    let all = [
        (p(20.0, 2e-4, Auto, [0.1, 0.1]), true),
        (p(20.0, 2e-3, Implicit, [0.1, -0.1]), true),
        (p(20.0, 2e-4, OneSided, [0.0, 0.0]), true),
        (p(20.0, 2e-3, Explicit, [0.0, 0.0]), true),
    ];
    for (nx, ny) in [(1, 40), (40, 1), (2, 2), (3, 257), (300, 7)] {
        run_cases(
            &format!("{nx}x{ny}"),
            GridSpec::new(nx, ny, 0.005),
            &all,
            0.02,
            100,
            nx > 1 && ny > 1,
        );
    }
}

#[test]
fn infinite_diffusion_is_uniform() {
    use DiffusionScheme::*;
    run_cases(
        "infinite diffusion",
        spec(),
        &[
            (p(20.0, f32::INFINITY, Auto, [0.0, 0.0]), true),
            (p(20.0, 2e-4, Auto, [0.0, 0.0]), false),
        ],
        0.02,
        20,
        false,
    );
}

#[test]
fn many_worlds_in_one_batch() {
    use DiffusionScheme::*;
    // 64 worlds x 3 pheromones of a 5 mm grid of a small arena, mixed parameters, in one batch.
    let spec = GridSpec::new(60, 40, 0.005);
    let cases: Vec<(GridParams, bool)> = (0..192)
        .map(|k| match k % 3 {
            0 => (p(20.0, 2e-6, Auto, [0.0, 0.0]), false),
            1 => (p(10.0 + k as f32, 2e-3, Auto, [0.0, 0.01]), true),
            _ => (p(30.0, 1e-4, OneSided, [0.0, 0.0]), false),
        })
        .collect();
    run_cases("batch of 64 worlds", spec, &cases, 0.02, 200, true);
}

/// The implicit solves go through workgroup memory in tiles of 64 lines x 32 cells: lines and cells
/// that fill no whole tile, several tiles along a line and several workgroups of lines give the
/// CPU's values bit for bit, in every field of the batch.
#[test]
fn implicit_solves_in_tiles_are_the_cpus_bit_for_bit() {
    use DiffusionScheme::*;
    let Some(ctx) = ctx() else { return };
    let cases = [
        (p(20.0, 2e-3, Implicit, [0.0, 0.0]), true),
        (p(f32::INFINITY, 2e-2, Implicit, [0.0, 0.0]), false),
    ];
    for (nx, ny) in [(97, 61), (64, 130), (33, 65), (200, 3), (1, 70), (70, 1)] {
        let spec = GridSpec::new(nx, ny, 0.005);
        let (mut cpu, mut gpu) = batch(ctx.clone(), spec, &cases, 3);
        for _ in 0..30 {
            cpu.iter_mut().for_each(|f| f.step(0.02));
            gpu.step(0.02).unwrap();
        }
        for (k, (g, c)) in gpu.read_all().unwrap().iter().zip(&cpu).enumerate() {
            let (_, same) = compare(g, c.values());
            assert_eq!(
                same,
                spec.len(),
                "{nx}x{ny}, case {k}: cells equal to the CPU's"
            );
        }
    }
}
