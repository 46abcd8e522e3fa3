//! colcos-gpu: a wgpu compute backend for the grid pheromone model of eq. (2), the screen of eq. (1)
//! and the colour sensors' screen sampling.
//!
//! * [`GpuContext`]: one adapter, device and queue ([`GpuContext::new`] with an [`AdapterPolicy`]).
//! * [`GpuGrids`]: a batch of grid fields of one [`GridSpec`](colcos_sim::field::GridSpec) (the fields of
//!   many worlds) stepped together in one dispatch per pass, with the same scheme, boundary conditions
//!   and f32 arithmetic as the CPU [`GridField`](colcos_sim::field::GridField); trail deposits along
//!   segments; values read back only when asked.
//! * [`screen`]: eq. (1) composed into 8-bit RGB on the GPU, and the sensors' footprint sampling, so that
//!   only the readings come back.
//! * [`backend`]: the [`FieldBackend`](colcos_sim::field::FieldBackend) that plugs the GPU into a
//!   [`World`](colcos_sim::world::World), and the `cpu`/`gpu`/`auto` choice.

pub mod backend;
mod grids;
pub mod screen;

pub use backend::{BackendSelection, GpuWorldBackend, install};
pub use grids::{Deposit, GpuGrids};
pub use screen::{GpuScreen, ScreenLayer, ScreenScene, SensorQuery, mean_levels};

use std::sync::Arc;

/// Errors of the GPU backend.
#[derive(Debug, thiserror::Error)]
pub enum GpuError {
    #[error(
        "no GPU adapter found (wgpu found no Vulkan/Metal/DX12/GL device{0}); use --backend cpu, or install a driver (for a software one on Debian: apt-get install mesa-vulkan-drivers libvulkan1)"
    )]
    NoAdapter(String),
    #[error("only a software adapter is present ({0}); `auto` prefers the CPU backend over it")]
    SoftwareOnly(String),
    #[error("could not open the GPU device {adapter}: {message}")]
    Device { adapter: String, message: String },
    #[error("GPU buffer too large: {what} needs {bytes} bytes, the adapter allows {limit}")]
    TooLarge {
        what: String,
        bytes: u64,
        limit: u64,
    },
    #[error("GPU read-back failed: {0}")]
    Readback(String),
    #[error("invalid input: {0}")]
    Invalid(String),
}

pub type Result<T> = std::result::Result<T, GpuError>;

/// Which adapters [`GpuContext::new`] accepts.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AdapterPolicy {
    /// Any adapter, software (lavapipe/llvmpipe, WARP, SwiftShader) included: what `--backend gpu` uses.
    Any,
    /// Hardware adapters only: what `--backend auto` uses (a software rasteriser is slower than the
    /// CPU backend).
    HardwareOnly,
}

/// One wgpu adapter, device and queue.
pub struct GpuContext {
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    pub info: wgpu::AdapterInfo,
    pub limits: wgpu::Limits,
    /// Whether the device has `SHADER_F64` (exact Gaussian sources on the screen and in the sensors).
    pub f64: bool,
}

/// True for software adapters: CPU device type, or llvmpipe/lavapipe/SwiftShader/WARP by name.
pub fn is_software(info: &wgpu::AdapterInfo) -> bool {
    let n = info.name.to_ascii_lowercase();
    info.device_type == wgpu::DeviceType::Cpu
        || n.contains("llvmpipe")
        || n.contains("lavapipe")
        || n.contains("swiftshader")
        || n.contains("softpipe")
        || n.contains("basic render")
}

/// One line describing an adapter: name, type, backend, driver.
pub fn describe(info: &wgpu::AdapterInfo) -> String {
    let soft = if is_software(info) { ", software" } else { "" };
    let driver = if info.driver.is_empty() {
        String::new()
    } else {
        format!(", driver {} {}", info.driver, info.driver_info)
    };
    format!(
        "{} ({:?}, {:?}{soft}{driver})",
        info.name, info.device_type, info.backend
    )
}

fn instance() -> wgpu::Instance {
    wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env())
}

/// Every adapter wgpu can see, best first (discrete, integrated, virtual, other, software).
pub fn adapters() -> Vec<wgpu::AdapterInfo> {
    let inst = instance();
    let mut v: Vec<_> = pollster::block_on(inst.enumerate_adapters(wgpu::Backends::all()))
        .iter()
        .map(|a| a.get_info())
        .collect();
    v.sort_by_key(rank);
    v
}

fn rank(info: &wgpu::AdapterInfo) -> u32 {
    if is_software(info) {
        return 9;
    }
    let t = match info.device_type {
        wgpu::DeviceType::DiscreteGpu => 0,
        wgpu::DeviceType::IntegratedGpu => 1,
        wgpu::DeviceType::VirtualGpu => 2,
        wgpu::DeviceType::Other => 3,
        wgpu::DeviceType::Cpu => 9,
    };
    // Prefer Vulkan/Metal/DX12 over GL for compute.
    t * 2 + u32::from(info.backend == wgpu::Backend::Gl)
}

impl GpuContext {
    /// Opens the best adapter the policy allows (see [`adapters`] for the order).
    pub fn new(policy: AdapterPolicy) -> Result<Arc<GpuContext>> {
        let inst = instance();
        let mut list = pollster::block_on(inst.enumerate_adapters(wgpu::Backends::all()));
        list.sort_by_key(|a| rank(&a.get_info()));
        let Some(adapter) = list.into_iter().next() else {
            return Err(GpuError::NoAdapter(String::new()));
        };
        let info = adapter.get_info();
        if policy == AdapterPolicy::HardwareOnly && is_software(&info) {
            return Err(GpuError::SoftwareOnly(describe(&info)));
        }
        Self::open(adapter)
    }

    fn open(adapter: wgpu::Adapter) -> Result<Arc<GpuContext>> {
        let info = adapter.get_info();
        let limits = adapter.limits();
        let f64 = adapter.features().contains(wgpu::Features::SHADER_F64);
        let required_features = if f64 {
            wgpu::Features::SHADER_F64
        } else {
            wgpu::Features::empty()
        };
        let desc = wgpu::DeviceDescriptor {
            label: Some("colcos-gpu"),
            required_features,
            required_limits: limits.clone(),
            ..Default::default()
        };
        let (device, queue) =
            pollster::block_on(adapter.request_device(&desc)).map_err(|e| GpuError::Device {
                adapter: describe(&info),
                message: e.to_string(),
            })?;
        Ok(Arc::new(GpuContext {
            device,
            queue,
            info,
            limits,
            f64,
        }))
    }

    /// One line describing the adapter in use.
    pub fn describe(&self) -> String {
        let f64 = if self.f64 { "" } else { " [no SHADER_F64]" };
        format!("{}{f64}", describe(&self.info))
    }

    pub fn is_software(&self) -> bool {
        is_software(&self.info)
    }

    /// The largest storage buffer binding, bytes.
    pub fn max_binding(&self) -> u64 {
        self.limits
            .max_storage_buffer_binding_size
            .min(self.limits.max_buffer_size)
    }

    /// Copies `bytes` bytes of `src` from `offset` into CPU memory (blocking).
    pub(crate) fn read_buffer(
        &self,
        src: &wgpu::Buffer,
        offset: u64,
        bytes: u64,
    ) -> Result<Vec<u8>> {
        if bytes == 0 {
            return Ok(Vec::new());
        }
        let staging = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("colcos-gpu readback"),
            size: bytes,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut enc = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("readback"),
            });
        enc.copy_buffer_to_buffer(src, offset, &staging, 0, bytes);
        self.queue.submit([enc.finish()]);
        let (tx, rx) = std::sync::mpsc::channel();
        staging.map_async(wgpu::MapMode::Read, .., move |r| {
            let _ = tx.send(r);
        });
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| GpuError::Readback(e.to_string()))?;
        match rx.recv() {
            Ok(Ok(())) => {}
            Ok(Err(e)) => return Err(GpuError::Readback(e.to_string())),
            Err(e) => return Err(GpuError::Readback(e.to_string())),
        }
        let out = {
            let view = staging
                .get_mapped_range(..)
                .map_err(|e| GpuError::Readback(format!("{e:?}")))?;
            view.to_vec()
        };
        staging.unmap();
        Ok(out)
    }

    /// Blocks until the queue is idle.
    pub fn wait(&self) -> Result<()> {
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map(|_| ())
            .map_err(|e| GpuError::Readback(e.to_string()))
    }
}

/// A storage buffer of at least `bytes` bytes (wgpu rejects empty bindings).
pub(crate) fn storage(
    ctx: &GpuContext,
    label: &str,
    bytes: u64,
    extra: wgpu::BufferUsages,
) -> wgpu::Buffer {
    ctx.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: bytes.max(256).next_multiple_of(4),
        usage: wgpu::BufferUsages::STORAGE
            | wgpu::BufferUsages::COPY_DST
            | wgpu::BufferUsages::COPY_SRC
            | extra,
        mapped_at_creation: false,
    })
}

pub(crate) fn check_size(ctx: &GpuContext, what: &str, bytes: u64) -> Result<()> {
    if bytes > ctx.max_binding() {
        return Err(GpuError::TooLarge {
            what: what.to_string(),
            bytes,
            limit: ctx.max_binding(),
        });
    }
    Ok(())
}
