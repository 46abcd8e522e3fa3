//! wgpu errors come back as `GpuError` values, never as panics from wgpu's default uncaptured-error
//! handler: a buffer above the adapter's limit, an invalid buffer size, a shader that does not compile,
//! errors outside any scope, and a lost (destroyed) device.
mod common;

use colcos_gpu::{AdapterPolicy, GpuContext, GpuError, GpuGrids, GpuWorldBackend, SharedBackend};
use colcos_sim::field::{DiffusionScheme, GridField, GridParams, GridSpec};
use glam::Vec2;

fn params() -> GridParams {
    GridParams {
        evaporation: 10.0,
        diffusion: 1e-5,
        scheme: DiffusionScheme::Auto,
        wind: Vec2::ZERO,
    }
}

fn spec() -> GridSpec {
    GridSpec::new(32, 24, 0.01)
}

#[test]
fn buffer_above_the_adapter_limit_is_an_error() {
    let Some(ctx) = common::ctx() else { return };
    let size = ctx.limits.max_buffer_size.saturating_add(1 << 20);
    let r = ctx.scoped("allocating a huge buffer", || {
        ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("too large"),
            size,
            usage: wgpu::BufferUsages::STORAGE,
            mapped_at_creation: false,
        })
    });
    match r {
        Err(GpuError::Wgpu { what, message }) => {
            assert_eq!(what, "allocating a huge buffer");
            eprintln!("as expected: {message}");
        }
        Err(e) => panic!("expected a wgpu error, got {e}"),
        Ok(_) => panic!("a {size}-byte buffer was accepted"),
    }
    // The device is still usable afterwards.
    let mut g = GpuGrids::new(ctx.clone(), spec(), &[params()]).expect("a small batch");
    g.step(0.02).expect("step after the error");
}

#[test]
fn invalid_buffer_size_is_an_error() {
    let Some(ctx) = common::ctx() else { return };
    // Mapped at creation, the size must be a multiple of 4 (COPY_BUFFER_ALIGNMENT).
    let r = ctx.scoped("allocating a 6-byte mapped buffer", || {
        ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("odd size"),
            size: 6,
            usage: wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: true,
        })
    });
    assert!(matches!(r, Err(GpuError::Wgpu { .. })), "{:?}", r.err());
}

#[test]
fn shader_that_does_not_compile_is_an_error() {
    let Some(ctx) = common::ctx() else { return };
    let r = ctx.scoped("compiling a broken shader", || {
        ctx.device
            .create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some("broken"),
                source: wgpu::ShaderSource::Wgsl("@compute fn main( { nonsense".into()),
            })
    });
    let Err(e) = r else {
        panic!("a broken shader compiled")
    };
    assert!(e.to_string().contains("compiling a broken shader"), "{e}");
}

#[test]
fn batch_above_the_binding_limit_is_an_error() {
    let Some(ctx) = common::ctx() else { return };
    let side = ((ctx.max_binding() / 8) as f64).sqrt() as usize + 2;
    let big = GridSpec::new(side, side, 0.001);
    match GpuGrids::new(ctx.clone(), big, &[params()]) {
        Err(GpuError::TooLarge { bytes, limit, .. }) => assert!(bytes > limit),
        Err(e) => panic!("expected TooLarge, got {e}"),
        Ok(_) => panic!("a batch above the binding limit was accepted"),
    }
}

/// A device of its own (destroying the shared one would break the other tests).
#[test]
fn lost_device_is_an_error_and_the_world_backend_falls_back() {
    if common::ctx().is_none() {
        return;
    }
    let ctx = GpuContext::new(AdapterPolicy::Any).expect("a second device");
    let cpu = GridField::new(spec(), params());
    let mut g = GpuGrids::from_fields(ctx.clone(), &[&cpu]).expect("batch");
    g.step(0.02).expect("a step before the loss");
    let sc = colcos_sim::scenario::Scenario::from_file(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../scenarios/three_trails.toml"
    ))
    .expect("scenario");
    let mut world = colcos_sim::world::World::new(&sc).expect("world");
    SharedBackend::on(ctx.clone())
        .install(&mut world)
        .expect("install");
    assert!(world.field_backend().unwrap().starts_with("gpu"));

    ctx.device.destroy();
    let _ = ctx.device.poll(wgpu::PollType::wait_indefinitely());
    match g.step(0.02) {
        Err(e @ (GpuError::DeviceLost { .. } | GpuError::Wgpu { .. })) => {
            eprintln!("as expected: {e}")
        }
        Err(e) => panic!("unexpected error kind: {e}"),
        Ok(()) => panic!("a step on a destroyed device succeeded"),
    }
    assert!(g.read_field(0).is_err());
    assert!(GpuGrids::new(ctx.clone(), spec(), &[params()]).is_err());
    assert!(GpuWorldBackend::new(ctx.clone(), world.pheromones()).is_err());
    // The world keeps stepping, on the CPU, and says so.
    world.step();
    world.step();
    let d = world.field_backend().unwrap();
    assert!(d.starts_with("cpu (the GPU"), "{d}");
}
