//! A batch of grid fields on the GPU: the same model, scheme and f32 arithmetic as
//! [`colcos_sim::field::GridField`], many fields per dispatch. Each field's step follows the same
//! [`StepPlan`](colcos_sim::field::StepPlan) as the CPU's.
mod deposit;
mod injection;
mod pipelines;
mod record;
mod step;

pub(crate) use deposit::DepRecord;
pub use deposit::Deposit;
pub(crate) use pipelines::FieldPipelines;

use crate::{GpuContext, GpuError, Result, check_size, storage};
use colcos_sim::field::{GridField, GridParams, GridSpec, StepPlan};
use record::{MAX_GROUPS, PlanEntry, UNIFORM_STRIDE};
use std::sync::Arc;

/// One field of a batch: its parameters and where its data lie.
struct FieldState {
    params: GridParams,
    decay_carry: f64,
    inj_offset: Option<u32>,
    /// Diffusion number the Thomas coefficients were built for.
    coef_r: Option<u32>,
    slot: u32,
}

/// Buffers a step refills instead of allocating: a vector env's batch fills megabytes of them a step,
/// and a fresh allocation of that size costs a page fault for every 4 KiB it touches.
#[derive(Default)]
struct Scratch {
    /// Each field's plan of the step.
    plans: Vec<Option<StepPlan>>,
    /// Every pass's plan entries, pass after pass.
    entries: Vec<PlanEntry>,
    /// Each deposit's record, its round, and the deposits round by round.
    made: Vec<Option<deposit::DepRecord>>,
    round_of: Vec<u32>,
    order: Vec<u32>,
    recs: Vec<deposit::DepRecord>,
    /// Deposits a field has had so far in a call.
    per_field: Vec<u32>,
}

/// A batch of grid fields of one [`GridSpec`] (e.g. the pheromones of many worlds), on the GPU.
///
/// Each field has its own [`GridParams`] and optional static injection map. [`GpuGrids::step`] advances
/// them all with one dispatch per pass; values stay on the GPU until [`GpuGrids::read_field`] or
/// [`GpuGrids::read_all`].
pub struct GpuGrids {
    ctx: Arc<GpuContext>,
    spec: GridSpec,
    fields: Vec<FieldState>,
    pipes: Arc<FieldPipelines>,
    vals: wgpu::Buffer,
    inj: wgpu::Buffer,
    inj_len: u32,
    inj_data: Vec<f32>,
    /// Offsets in `inj_data` of the distinct maps stored there: fields with equal maps (the worlds of
    /// one scenario) share one copy.
    inj_maps: Vec<u32>,
    coef: wgpu::Buffer,
    plan: wgpu::Buffer,
    uniforms: wgpu::Buffer,
    deps: wgpu::Buffer,
    bind: Option<wgpu::BindGroup>,
    scratch: Scratch,
}

impl GpuGrids {
    /// `params.len()` fields of `spec`, all zero, no injection maps.
    pub fn new(ctx: Arc<GpuContext>, spec: GridSpec, params: &[GridParams]) -> Result<Self> {
        let n = spec.len() as u64;
        let bytes = 2 * n * params.len() as u64 * 4;
        check_size(
            &ctx,
            "field values (2 slots x fields x cells x 4 bytes)",
            bytes,
        )?;
        if params.len() > MAX_GROUPS as usize {
            return Err(GpuError::Invalid(format!(
                "{} fields in one batch; at most {MAX_GROUPS}",
                params.len()
            )));
        }
        if spec.nx == 0 || spec.ny == 0 {
            return Err(GpuError::Invalid("empty grid".into()));
        }
        let pipes = FieldPipelines::get(&ctx)?;
        let nf = params.len().max(1) as u64;
        let (vals, coef, inj, plan, deps, uniforms) =
            ctx.scoped("allocating the field buffers", || {
                let vals = storage(
                    &ctx,
                    "colcos field values",
                    bytes,
                    wgpu::BufferUsages::empty(),
                );
                let coef = storage(
                    &ctx,
                    "colcos thomas coefficients",
                    nf * 2 * (spec.nx + spec.ny) as u64 * 4,
                    wgpu::BufferUsages::empty(),
                );
                let inj = storage(
                    &ctx,
                    "colcos injection maps",
                    16,
                    wgpu::BufferUsages::empty(),
                );
                let plan = storage(
                    &ctx,
                    "colcos plan",
                    nf * 8 * 32,
                    wgpu::BufferUsages::empty(),
                );
                let deps = storage(
                    &ctx,
                    "colcos deposits",
                    64 * 64,
                    wgpu::BufferUsages::empty(),
                );
                let uniforms = ctx.device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("colcos pass uniforms"),
                    size: UNIFORM_STRIDE * 16,
                    usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                });
                (vals, coef, inj, plan, deps, uniforms)
            })?;
        let fields = params
            .iter()
            .map(|&p| FieldState {
                params: p,
                decay_carry: 0.0,
                inj_offset: None,
                coef_r: None,
                slot: 0,
            })
            .collect();
        Ok(GpuGrids {
            ctx,
            spec,
            fields,
            pipes,
            vals,
            inj,
            inj_len: 0,
            inj_data: Vec::new(),
            inj_maps: Vec::new(),
            coef,
            plan,
            uniforms,
            deps,
            bind: None,
            scratch: Scratch::default(),
        })
    }

    /// A batch holding copies of CPU grid fields (values, parameters, static injection), all of one spec.
    pub fn from_fields(ctx: Arc<GpuContext>, fields: &[&GridField]) -> Result<Self> {
        let Some(first) = fields.first() else {
            return Err(GpuError::Invalid("no fields".into()));
        };
        let spec = *first.spec();
        if fields.iter().any(|f| *f.spec() != spec) {
            return Err(GpuError::Invalid(
                "all fields of a batch must share one grid spec".into(),
            ));
        }
        let params: Vec<GridParams> = fields.iter().map(|f| *f.params()).collect();
        let mut g = Self::new(ctx, spec, &params)?;
        for (i, f) in fields.iter().enumerate() {
            g.write_field(i, f.values())?;
            g.set_static_injection(i, f.static_injection())?;
        }
        Ok(g)
    }

    pub fn context(&self) -> &Arc<GpuContext> {
        &self.ctx
    }
    pub fn spec(&self) -> &GridSpec {
        &self.spec
    }
    pub fn len(&self) -> usize {
        self.fields.len()
    }
    pub fn is_empty(&self) -> bool {
        self.fields.is_empty()
    }
    pub fn params(&self, field: usize) -> &GridParams {
        &self.fields[field].params
    }
    pub fn set_params(&mut self, field: usize, params: GridParams) {
        self.fields[field].params = params;
    }
    /// The buffer holding every field (two slots each); see [`GpuGrids::field_offset`].
    pub fn values_buffer(&self) -> &wgpu::Buffer {
        &self.vals
    }
    /// Offset, in f32 elements, of the current values of `field` in [`GpuGrids::values_buffer`].
    pub fn field_offset(&self, field: usize) -> u64 {
        (2 * field as u64 + self.fields[field].slot as u64) * self.spec.len() as u64
    }

    /// Overwrites the values of `field`.
    pub fn write_field(&mut self, field: usize, values: &[f32]) -> Result<()> {
        if values.len() != self.spec.len() {
            return Err(GpuError::Invalid(format!(
                "field {field}: {} values for {} cells",
                values.len(),
                self.spec.len()
            )));
        }
        self.ctx.scoped("writing field values", || {
            self.ctx.queue.write_buffer(
                &self.vals,
                self.field_offset(field) * 4,
                bytemuck::cast_slice(values),
            )
        })
    }

    /// Sets every field to zero.
    pub fn clear(&mut self) -> Result<()> {
        self.ctx.scoped("clearing the fields", || {
            let mut enc = self.ctx.device.create_command_encoder(&Default::default());
            enc.clear_buffer(&self.vals, 0, None);
            self.ctx.queue.submit([enc.finish()]);
        })
    }

    /// Reads the values of `field` back (blocking).
    pub fn read_field(&self, field: usize) -> Result<Vec<f32>> {
        let n = self.spec.len() as u64;
        let bytes = self
            .ctx
            .read_buffer(&self.vals, self.field_offset(field) * 4, n * 4)?;
        Ok(bytemuck::cast_slice(&bytes).to_vec())
    }

    /// Reads every field back (blocking), one `Vec` per field.
    pub fn read_all(&self) -> Result<Vec<Vec<f32>>> {
        let n = self.spec.len();
        let bytes =
            self.ctx
                .read_buffer(&self.vals, 0, 2 * n as u64 * self.fields.len() as u64 * 4)?;
        let all: &[f32] = bytemuck::cast_slice(&bytes);
        Ok(self
            .fields
            .iter()
            .enumerate()
            .map(|(f, st)| all[(2 * f + st.slot as usize) * n..][..n].to_vec())
            .collect())
    }
}
