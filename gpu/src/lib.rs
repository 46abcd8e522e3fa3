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
//! * [`worlds`]: a vector environment's worlds' grid pheromones resident on the GPU, stepped, laid
//!   and sensed together each step, only the sensors' readings read back.
//! * [`backend`]: the [`FieldBackend`](colcos_sim::field::FieldBackend) that plugs the GPU into a
//!   [`World`](colcos_sim::world::World), and the `cpu`/`gpu`/`auto` choice.

pub mod backend;
mod grids;
mod program;

/// The wgpu this crate is built on (for [`GpuContext`]'s device and buffers).
pub use wgpu;
pub mod screen;
pub mod worlds;

pub use backend::{BackendSelection, GpuWorldBackend, SharedBackend, install};
pub use grids::{Deposit, GpuGrids};
pub use screen::{GpuScreen, ScreenLayer, ScreenScene, SensorQuery, mean_levels};
pub use worlds::WorldFields;

use std::sync::{Arc, Mutex};

/// Errors of the GPU backend.
#[derive(Debug, thiserror::Error)]
pub enum GpuError {
    #[error(
        "no GPU adapter found (wgpu found no Vulkan/Metal/DX12 device{0}); use --backend cpu, or install a driver (for a software one on Debian: apt-get install mesa-vulkan-drivers libvulkan1)"
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
    /// A validation, out-of-memory or internal error that wgpu reported (caught by an error scope or
    /// the device's uncaptured-error handler, never a panic).
    #[error("GPU error while {what}: {message}")]
    Wgpu { what: String, message: String },
    /// The device was lost (driver reset, GPU removed or hung, or destroyed); it cannot be used again.
    #[error(
        "the GPU device {adapter} was lost ({reason}); make a new GpuContext, or use the CPU backend"
    )]
    DeviceLost { adapter: String, reason: String },
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
///
/// wgpu's default reaction to a validation error, an out-of-memory error or a lost device is a panic
/// from its uncaptured-error handler. A `GpuContext` installs its own handler instead, and every
/// operation of this crate runs inside error scopes ([`GpuContext::scoped`]), so those errors become
/// [`GpuError::Wgpu`] and [`GpuError::DeviceLost`] values.
pub struct GpuContext {
    /// The instance the adapter came from: a window's surface must be made from it to share the device.
    pub instance: wgpu::Instance,
    pub adapter: wgpu::Adapter,
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    pub info: wgpu::AdapterInfo,
    pub limits: wgpu::Limits,
    /// Whether the device has `SHADER_F64` (exact Gaussian sources on the screen and in the sensors).
    pub f64: bool,
    /// Errors no scope caught (from other threads or wgpu's own work), oldest first.
    uncaptured: Arc<Mutex<Vec<String>>>,
    /// Why the device was lost, once it is.
    lost: Arc<Mutex<Option<String>>>,
    /// The field pipelines, compiled once per device and shared by every [`GpuGrids`] on it.
    pub(crate) field_pipelines: Mutex<Option<Arc<grids::FieldPipelines>>>,
}

/// A wgpu error as one line (its description; wgpu's are multi-line "Caused by" chains).
fn error_text(e: &wgpu::Error) -> String {
    let kind = match e {
        wgpu::Error::OutOfMemory { .. } => "out of GPU memory: ",
        wgpu::Error::Validation { .. } => "",
        wgpu::Error::Internal { .. } => "internal error: ",
    };
    let mut text = e.to_string();
    let mut src = std::error::Error::source(e);
    while let Some(s) = src {
        let t = s.to_string();
        if !text.contains(&t) {
            text.push_str(": ");
            text.push_str(&t);
        }
        src = s.source();
    }
    let text = text.split_whitespace().collect::<Vec<_>>().join(" ");
    format!("{kind}{text}")
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
    let t = match info.device_type {
        _ if is_software(info) => 9,
        wgpu::DeviceType::DiscreteGpu => 0,
        wgpu::DeviceType::IntegratedGpu => 1,
        wgpu::DeviceType::VirtualGpu => 2,
        wgpu::DeviceType::Other => 3,
        wgpu::DeviceType::Cpu => 9,
    };
    // Prefer Vulkan/Metal/DX12 over GL for compute, software adapters included: Mesa's GL llvmpipe
    // (present wherever Mesa's GL is) has no SHADER_F64, its Vulkan lavapipe has.
    t * 2 + u32::from(info.backend == wgpu::Backend::Gl)
}

/// Whether [`GpuContext::new`] may open this adapter: not a GL one unless `gl_requested`
/// (`WGPU_BACKEND` names GL). wgpu's GL backend puts every call of a device behind one context lock
/// that panics after 6 s, and a thread waiting on a long dispatch holds it (seen with llvmpipe and
/// parallel tests).
fn usable(info: &wgpu::AdapterInfo, gl_requested: bool) -> bool {
    info.backend != wgpu::Backend::Gl || gl_requested
}

impl GpuContext {
    /// Opens the best adapter the policy allows (see [`adapters`] for the order).
    pub fn new(policy: AdapterPolicy) -> Result<Arc<GpuContext>> {
        let inst = instance();
        let mut list = pollster::block_on(inst.enumerate_adapters(wgpu::Backends::all()));
        list.sort_by_key(|a| rank(&a.get_info()));
        let gl = wgpu::Backends::from_env().is_some_and(|b| b.contains(wgpu::Backends::GL));
        let (open, skipped): (Vec<_>, Vec<_>) =
            list.into_iter().partition(|a| usable(&a.get_info(), gl));
        let Some(adapter) = open.into_iter().next() else {
            let why = if skipped.is_empty() {
                String::new()
            } else {
                let names: Vec<_> = skipped.iter().map(|a| describe(&a.get_info())).collect();
                format!(
                    "; skipped {} (wgpu's GL backend panics when threads share its device; WGPU_BACKEND=gl uses it anyway)",
                    names.join(", ")
                )
            };
            return Err(GpuError::NoAdapter(why));
        };
        let info = adapter.get_info();
        if policy == AdapterPolicy::HardwareOnly && is_software(&info) {
            return Err(GpuError::SoftwareOnly(describe(&info)));
        }
        Self::open(inst, adapter)
    }

    fn open(instance: wgpu::Instance, adapter: wgpu::Adapter) -> Result<Arc<GpuContext>> {
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
        let uncaptured = Arc::new(Mutex::new(Vec::new()));
        let lost = Arc::new(Mutex::new(None));
        {
            let uncaptured = uncaptured.clone();
            device.on_uncaptured_error(Arc::new(move |e: wgpu::Error| {
                let mut v = uncaptured.lock().unwrap_or_else(|p| p.into_inner());
                // Keep the first few: later ones are usually consequences.
                if v.len() < 16 {
                    v.push(error_text(&e));
                }
            }));
        }
        {
            let lost = lost.clone();
            device.set_device_lost_callback(move |reason, message| {
                let mut l = lost.lock().unwrap_or_else(|p| p.into_inner());
                if l.is_none() {
                    let message = message.split_whitespace().collect::<Vec<_>>().join(" ");
                    *l = Some(if message.is_empty() {
                        format!("{reason:?}")
                    } else {
                        format!("{reason:?}: {message}")
                    });
                }
            });
        }
        Ok(Arc::new(GpuContext {
            instance,
            adapter,
            device,
            queue,
            info,
            limits,
            f64,
            uncaptured,
            lost,
            field_pipelines: Mutex::new(None),
        }))
    }

    /// Runs `f` (which creates resources on, records for or submits to this device) inside
    /// validation, out-of-memory and internal error scopes; what wgpu reports there comes back as
    /// [`GpuError::Wgpu`] naming `what`, a lost device as [`GpuError::DeviceLost`]. Errors that no
    /// scope caught earlier (another thread's, or wgpu's own) are reported here too.
    ///
    /// Scopes are per thread: `f` must not hand its GPU work to another thread.
    pub fn scoped<T>(&self, what: &str, f: impl FnOnce() -> T) -> Result<T> {
        self.check_lost()?;
        let oom = self.device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
        let internal = self.device.push_error_scope(wgpu::ErrorFilter::Internal);
        let validation = self.device.push_error_scope(wgpu::ErrorFilter::Validation);
        let out = f();
        let errors = [
            pollster::block_on(validation.pop()),
            pollster::block_on(internal.pop()),
            pollster::block_on(oom.pop()),
        ];
        self.check_lost()?;
        if let Some(e) = errors.iter().flatten().next() {
            return Err(GpuError::Wgpu {
                what: what.to_string(),
                message: error_text(e),
            });
        }
        self.check_uncaptured(what)?;
        Ok(out)
    }

    /// [`GpuError::DeviceLost`] once the device is lost.
    pub fn check_lost(&self) -> Result<()> {
        match &*self.lost.lock().unwrap_or_else(|p| p.into_inner()) {
            Some(reason) => Err(GpuError::DeviceLost {
                adapter: describe(&self.info),
                reason: reason.clone(),
            }),
            None => Ok(()),
        }
    }

    /// The errors wgpu reported outside any scope since the last call, as one [`GpuError::Wgpu`].
    pub fn check_uncaptured(&self, what: &str) -> Result<()> {
        let errs = std::mem::take(&mut *self.uncaptured.lock().unwrap_or_else(|p| p.into_inner()));
        if errs.is_empty() {
            return Ok(());
        }
        Err(GpuError::Wgpu {
            what: format!("{what} (reported outside an error scope)"),
            message: errs.join("; "),
        })
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
        self.read_buffer_with(src, offset, bytes, <[u8]>::to_vec)
    }

    /// Hands `bytes` bytes of `src` from `offset` to `f` (blocking), without a copy of them of our own.
    pub(crate) fn read_buffer_with<T>(
        &self,
        src: &wgpu::Buffer,
        offset: u64,
        bytes: u64,
        f: impl FnOnce(&[u8]) -> T,
    ) -> Result<T> {
        if bytes == 0 {
            return Ok(f(&[]));
        }
        let (tx, rx) = std::sync::mpsc::channel();
        let staging = self.scoped("reading a buffer back", || {
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
            staging.map_async(wgpu::MapMode::Read, .., move |r| {
                let _ = tx.send(r);
            });
            staging
        })?;
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| self.lost_or(GpuError::Readback(e.to_string())))?;
        match rx.recv() {
            Ok(Ok(())) => {}
            Ok(Err(e)) => return Err(self.lost_or(GpuError::Readback(e.to_string()))),
            Err(e) => return Err(self.lost_or(GpuError::Readback(e.to_string()))),
        }
        let out = {
            let view = staging
                .get_mapped_range(..)
                .map_err(|e| GpuError::Readback(format!("{e:?}")))?;
            f(&view)
        };
        staging.unmap();
        Ok(out)
    }

    /// Blocks until the queue is idle.
    pub fn wait(&self) -> Result<()> {
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map(|_| ())
            .map_err(|e| self.lost_or(GpuError::Readback(e.to_string())))?;
        self.check_lost()?;
        self.check_uncaptured("waiting for the GPU")
    }

    /// `e`, or [`GpuError::DeviceLost`] when the device is lost (the likelier cause).
    fn lost_or(&self, e: GpuError) -> GpuError {
        self.check_lost().err().unwrap_or(e)
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

#[cfg(test)]
mod tests {
    use super::{rank, usable};
    use wgpu::{AdapterInfo, Backend, DeviceType};

    fn adapter(name: &str, device_type: DeviceType, backend: Backend) -> AdapterInfo {
        AdapterInfo {
            name: name.into(),
            ..AdapterInfo::new(device_type, backend)
        }
    }

    /// Hardware first (discrete before integrated), Vulkan before GL, and among software adapters
    /// lavapipe (Vulkan, with SHADER_F64) before llvmpipe's GL (without it).
    #[test]
    fn adapters_rank_hardware_then_vulkan_before_gl() {
        let mut list = [
            adapter(
                "llvmpipe (LLVM 15.0.6, 256 bits)",
                DeviceType::Cpu,
                Backend::Gl,
            ),
            adapter(
                "llvmpipe (LLVM 15.0.6, 256 bits)",
                DeviceType::Cpu,
                Backend::Vulkan,
            ),
            adapter("Intel UHD", DeviceType::IntegratedGpu, Backend::Gl),
            adapter("Intel UHD", DeviceType::IntegratedGpu, Backend::Vulkan),
            adapter("NVIDIA H200", DeviceType::DiscreteGpu, Backend::Vulkan),
        ];
        list.sort_by_key(rank);
        let opened = |gl: bool| -> Vec<_> {
            list.iter()
                .filter(|a| usable(a, gl))
                .map(|a| a.backend)
                .collect()
        };
        assert_eq!(opened(false), [Backend::Vulkan; 3], "GL only on request");
        assert_eq!(opened(true).len(), list.len());
        let order: Vec<_> = list.iter().map(|a| (a.device_type, a.backend)).collect();
        assert_eq!(
            order,
            [
                (DeviceType::DiscreteGpu, Backend::Vulkan),
                (DeviceType::IntegratedGpu, Backend::Vulkan),
                (DeviceType::IntegratedGpu, Backend::Gl),
                (DeviceType::Cpu, Backend::Vulkan),
                (DeviceType::Cpu, Backend::Gl),
            ]
        );
    }
}
