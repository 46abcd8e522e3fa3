//! The GPU as a [`FieldBackend`] of a [`World`], and the `cpu` / `gpu` / `auto` choice.
//!
//! A world's injection (trail deposits) and its sensors read the CPU copy of the fields, so
//! [`GpuWorldBackend`] mirrors: each step it uploads the grid fields, steps them on the GPU and reads
//! them back. That keeps every other part of the world unchanged and gives the GPU's numbers, but the
//! transfers cost more than the step itself for small grids; the batched API ([`crate::GpuGrids`] with
//! [`crate::GpuGrids::deposit`] and [`crate::screen::GpuScreen::sense`]) keeps the fields on the GPU.
use crate::{AdapterPolicy, GpuContext, GpuError, GpuGrids, Result};
use colcos_sim::field::{
    BackendChoice, FieldBackend, FieldModel, GridField, GridParams, Pheromone,
};
use colcos_sim::world::World;
use std::sync::Arc;

/// What [`install`] chose.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum BackendSelection {
    /// The CPU steps the fields; `reason` says why (asked for, no hardware adapter, no grid fields).
    Cpu { reason: String },
    /// The GPU steps the fields, on this adapter.
    Gpu { adapter: String },
}

impl std::fmt::Display for BackendSelection {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            BackendSelection::Cpu { reason } => write!(f, "cpu ({reason})"),
            BackendSelection::Gpu { adapter } => write!(f, "gpu: {adapter}"),
        }
    }
}

/// The device `choice` asks for: `None` for the CPU. `gpu` takes any adapter (software included) and is
/// an error without one; `auto` takes a hardware adapter only, else the CPU.
pub fn context_for(choice: BackendChoice) -> Result<(Option<Arc<GpuContext>>, String)> {
    match choice {
        BackendChoice::Cpu => Ok((None, "asked for".into())),
        BackendChoice::Gpu => GpuContext::new(AdapterPolicy::Any).map(|c| (Some(c), String::new())),
        BackendChoice::Auto => match GpuContext::new(AdapterPolicy::HardwareOnly) {
            Ok(c) => Ok((Some(c), String::new())),
            Err(GpuError::SoftwareOnly(a)) => Ok((
                None,
                format!("auto: only a software adapter, {a}, which is slower than the CPU"),
            )),
            Err(GpuError::NoAdapter(_)) => Ok((None, "auto: no GPU adapter".into())),
            Err(e) => Ok((None, format!("auto: the GPU could not be opened: {e}"))),
        },
    }
}

/// Installs the backend `choice` in `world` (see [`context_for`]) and says what it chose.
pub fn install(world: &mut World, choice: BackendChoice) -> Result<BackendSelection> {
    SharedBackend::resolve(choice)?.install(world)
}

/// A backend choice resolved once, for any number of worlds: one device (or the CPU) for all, so that
/// a vector env's worlds, rebuilt every episode, do not each open a device and compile the shaders.
#[derive(Clone)]
pub struct SharedBackend {
    ctx: Option<Arc<GpuContext>>,
    /// Why the CPU, when it is the CPU.
    reason: String,
}

impl SharedBackend {
    /// The device `choice` asks for (see [`context_for`]): `gpu` without an adapter is an error,
    /// `auto` falls back to the CPU.
    pub fn resolve(choice: BackendChoice) -> Result<Self> {
        let (ctx, reason) = context_for(choice)?;
        Ok(SharedBackend { ctx, reason })
    }

    /// A backend on an open device.
    pub fn on(ctx: Arc<GpuContext>) -> Self {
        SharedBackend {
            ctx: Some(ctx),
            reason: String::new(),
        }
    }

    /// The device, or `None` for the CPU.
    pub fn context(&self) -> Option<&Arc<GpuContext>> {
        self.ctx.as_ref()
    }

    /// What the choice resolved to: `gpu: <adapter>` or `cpu (<reason>)`.
    pub fn selection(&self) -> BackendSelection {
        match &self.ctx {
            Some(c) => BackendSelection::Gpu {
                adapter: c.describe(),
            },
            None => BackendSelection::Cpu {
                reason: self.reason.clone(),
            },
        }
    }

    /// Installs the backend in `world` and says what it chose (the CPU for a world without grid
    /// pheromones).
    pub fn install(&self, world: &mut World) -> Result<BackendSelection> {
        let Some(ctx) = self.ctx.clone() else {
            world.set_field_backend(None);
            return Ok(self.selection());
        };
        match GpuWorldBackend::new(ctx, world.pheromones())? {
            Some(b) => {
                let adapter = b.ctx.describe();
                world.set_field_backend(Some(Box::new(b)));
                Ok(BackendSelection::Gpu { adapter })
            }
            None => {
                world.set_field_backend(None);
                Ok(BackendSelection::Cpu {
                    reason: "no grid pheromones to step".into(),
                })
            }
        }
    }
}

/// Steps a world's grid pheromones on the GPU (Gaussian ones on the CPU: they are analytic).
pub struct GpuWorldBackend {
    ctx: Arc<GpuContext>,
    grids: GpuGrids,
    /// Batch field of each pheromone (None: not a grid).
    map: Vec<Option<usize>>,
    params: Vec<GridParams>,
    injection: Vec<Option<Vec<f32>>>,
    failed: bool,
}

impl GpuWorldBackend {
    /// A backend for these pheromones, or `None` if none is a grid.
    pub fn new(ctx: Arc<GpuContext>, pheromones: &[Pheromone]) -> Result<Option<Self>> {
        let mut map = Vec::new();
        let mut fields: Vec<&GridField> = Vec::new();
        for p in pheromones {
            match &p.model {
                FieldModel::Grid(g) => {
                    map.push(Some(fields.len()));
                    fields.push(g);
                }
                FieldModel::Gaussian(_) => map.push(None),
            }
        }
        if fields.is_empty() {
            return Ok(None);
        }
        let grids = GpuGrids::from_fields(ctx.clone(), &fields)?;
        let params = fields.iter().map(|f| *f.params()).collect();
        let injection = fields
            .iter()
            .map(|f| f.static_injection().map(|j| j.to_vec()))
            .collect();
        Ok(Some(GpuWorldBackend {
            ctx,
            grids,
            map,
            params,
            injection,
            failed: false,
        }))
    }

    pub fn grids(&self) -> &GpuGrids {
        &self.grids
    }

    fn try_step(&mut self, pheromones: &mut [Pheromone], dt: f32) -> Result<()> {
        if pheromones.len() != self.map.len() {
            return Err(GpuError::Invalid("the world's pheromones changed".into()));
        }
        for (p, m) in pheromones.iter().zip(&self.map) {
            let (FieldModel::Grid(g), Some(f)) = (&p.model, m) else {
                continue;
            };
            let f = *f;
            self.grids.write_field(f, g.values())?;
            if *g.params() != self.params[f] {
                self.params[f] = *g.params();
                self.grids.set_params(f, self.params[f]);
            }
            if g.static_injection() != self.injection[f].as_deref() {
                self.injection[f] = g.static_injection().map(|j| j.to_vec());
                self.grids.set_static_injection(f, g.static_injection())?;
            }
        }
        self.grids.step(dt)?;
        let all = self.grids.read_all()?;
        for (p, m) in pheromones.iter_mut().zip(&self.map) {
            match (&mut p.model, m) {
                (FieldModel::Grid(g), Some(f)) => g.values_mut().copy_from_slice(&all[*f]),
                _ => p.step(dt),
            }
        }
        Ok(())
    }
}

impl FieldBackend for GpuWorldBackend {
    fn describe(&self) -> String {
        if self.failed {
            format!("cpu (the GPU {} failed)", self.ctx.describe())
        } else {
            format!("gpu: {}", self.ctx.describe())
        }
    }

    fn step(&mut self, pheromones: &mut [Pheromone], dt: f32) {
        if !self.failed {
            match self.try_step(pheromones, dt) {
                Ok(()) => return,
                Err(e) => {
                    log::warn!("colcos-gpu: {e}; the CPU steps the fields from now on");
                    self.failed = true;
                }
            }
        }
        pheromones.iter_mut().for_each(|p| p.step(dt));
    }
}
