//! A batch of grid fields on the GPU: the same model, scheme and f32 arithmetic as
//! [`colcos_sim::field::GridField`], many fields per dispatch.
use crate::{GpuContext, GpuError, Result, check_size, storage};
use bytemuck::{Pod, Zeroable};
use colcos_sim::field::{DiffusionScheme, GridField, GridParams, GridSpec, Kernel};
use glam::Vec2;
use std::sync::Arc;

/// Largest explicit diffusion number `d dt / h^2` per (sub-)step (as the CPU backend).
const EXPLICIT_MAX_R: f32 = 0.25;
/// Largest one-sided number per sub-step (as the CPU backend).
const ONE_SIDED_MAX_S: f32 = 0.5;
/// Largest Courant number per wind sub-step (as the CPU backend).
const WIND_MAX_CFL: f32 = 0.5;
/// Bytes between two dispatch uniforms (the dynamic-offset alignment wgpu guarantees to accept).
const UNIFORM_STRIDE: u64 = 256;
const MAX_GROUPS: u32 = 65535;

#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
struct PlanEntry {
    on: u32,
    src: u32,
    inj: i32,
    coef: u32,
    a: f32,
    b: f32,
    r: f32,
    c: f32,
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
struct PassUniform {
    index: u32,
    nfields: u32,
    nx: u32,
    ny: u32,
    groups_x: u32,
    count: u32,
    cell: f32,
    _pad: u32,
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
struct DepRecord {
    field: u32,
    slot: u32,
    i0: u32,
    j0: u32,
    w: u32,
    h: u32,
    kind: u32,
    _pad: u32,
    ax: f32,
    ay: f32,
    abx: f32,
    aby: f32,
    len2: f32,
    support: f32,
    param: f32,
    amount: f32,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    Evaporate,
    Explicit,
    OneSided,
    XSolve,
    YSolve,
    AdvectX,
    AdvectY,
}

impl Kind {
    /// Whether the pass writes the other slot (ping-pong) rather than in place.
    fn flips(self) -> bool {
        self != Kind::Evaporate
    }
}

/// One trail deposit: `amount * kernel(distance to segment a-b)` added to every cell near the segment
/// of field `field`, exactly as [`GridField::deposit_segment`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Deposit {
    pub field: usize,
    pub kernel: Kernel,
    pub a: Vec2,
    pub b: Vec2,
    pub amount: f32,
}

struct FieldState {
    params: GridParams,
    decay_carry: f64,
    inj_offset: Option<u32>,
    /// Diffusion number the Thomas coefficients were built for.
    coef_r: Option<u32>,
    slot: u32,
}

/// The field shader's pipelines and their layout: compiled once per device (see
/// [`FieldPipelines::get`]) and shared by every batch on it, so that making a batch (one per world, for a
/// vector env) costs only its buffers.
pub(crate) struct FieldPipelines {
    layout: wgpu::BindGroupLayout,
    evaporate: wgpu::ComputePipeline,
    explicit: wgpu::ComputePipeline,
    one_sided: wgpu::ComputePipeline,
    xsolve: wgpu::ComputePipeline,
    ysolve: wgpu::ComputePipeline,
    advect_x: wgpu::ComputePipeline,
    advect_y: wgpu::ComputePipeline,
    deposit: wgpu::ComputePipeline,
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
    coef: wgpu::Buffer,
    plan: wgpu::Buffer,
    uniforms: wgpu::Buffer,
    deps: wgpu::Buffer,
    bind: Option<wgpu::BindGroup>,
}

/// Precomputed Thomas coefficients (m, cp): exactly the CPU backend's.
fn thomas(n: usize, r: f32) -> (Vec<f32>, Vec<f32>) {
    colcos_sim::field::thomas_coefficients(n, r)
}

fn substeps(x: f32, max: f32) -> usize {
    if x <= max {
        1
    } else {
        ((x / max).ceil() as usize).max(1)
    }
}

/// Index range `[lo, hi)` of the cells whose centres may lie within `[lo_m, hi_m]` (as the CPU's).
fn cell_range(cell: f32, lo_m: f32, hi_m: f32, n: usize) -> (usize, usize) {
    let lo = ((lo_m / cell - 0.5).floor().max(0.0) as usize).min(n);
    let hi = (((hi_m / cell - 0.5).ceil() + 1.0).max(0.0) as usize).min(n);
    (lo, hi.max(lo))
}

/// Workgroup counts (x, y) covering `items` with `per` items per group, folded under the 65,535 limit.
fn groups(items: usize, per: usize) -> (u32, u32) {
    let g = items.div_ceil(per).max(1) as u64;
    let gx = g.min(MAX_GROUPS as u64);
    (gx as u32, g.div_ceil(gx) as u32)
}

/// The field shader; with f64 the Gaussian deposit kernel's `exp` is computed in f64 and rounded, which
/// matches the CPU's `expf` (nearly always bit for bit), otherwise the GPU's f32 `exp` (within 1e-6).
fn field_source(f64: bool) -> String {
    let kexp = if f64 {
        format!(
            "{}\nfn kexp(x: f32) -> f32 {{ return f32(exp64(f64(x))); }}",
            crate::screen::EXP64
        )
    } else {
        "fn kexp(x: f32) -> f32 { return exp(x); }".to_string()
    };
    include_str!("field.wgsl").replace("//KEXP//", &kexp)
}

impl FieldPipelines {
    /// The context's pipelines, compiled on first use.
    fn get(ctx: &GpuContext) -> Result<Arc<FieldPipelines>> {
        let mut slot = ctx
            .field_pipelines
            .lock()
            .unwrap_or_else(|p| p.into_inner());
        if let Some(p) = slot.as_ref() {
            return Ok(p.clone());
        }
        let p = Arc::new(ctx.scoped("compiling the field shader", || Self::new(ctx))?);
        *slot = Some(p.clone());
        Ok(p)
    }

    fn new(ctx: &GpuContext) -> FieldPipelines {
        let device = &ctx.device;
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("colcos field.wgsl"),
            source: wgpu::ShaderSource::Wgsl(field_source(ctx.f64).into()),
        });
        let entry =
            |binding: u32, ty: wgpu::BufferBindingType, dynamic: bool| wgpu::BindGroupLayoutEntry {
                binding,
                visibility: wgpu::ShaderStages::COMPUTE,
                ty: wgpu::BindingType::Buffer {
                    ty,
                    has_dynamic_offset: dynamic,
                    min_binding_size: None,
                },
                count: None,
            };
        let ro = wgpu::BufferBindingType::Storage { read_only: true };
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("colcos field layout"),
            entries: &[
                entry(
                    0,
                    wgpu::BufferBindingType::Storage { read_only: false },
                    false,
                ),
                entry(1, ro, false),
                entry(2, wgpu::BufferBindingType::Uniform, true),
                entry(3, ro, false),
                entry(4, ro, false),
                entry(5, ro, false),
            ],
        });
        let pl = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("colcos field pipeline layout"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipe = |name: &str| {
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(name),
                layout: Some(&pl),
                module: &module,
                entry_point: Some(name),
                compilation_options: Default::default(),
                cache: None,
            })
        };
        FieldPipelines {
            evaporate: pipe("evaporate"),
            explicit: pipe("explicit_step"),
            one_sided: pipe("one_sided"),
            xsolve: pipe("xsolve"),
            ysolve: pipe("ysolve"),
            advect_x: pipe("advect_x"),
            advect_y: pipe("advect_y"),
            deposit: pipe("deposit"),
            layout,
        }
    }
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
            coef,
            plan,
            uniforms,
            deps,
            bind: None,
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

    /// Sets (or removes) the static injection map `J` of `field`.
    pub fn set_static_injection(&mut self, field: usize, j: Option<&[f32]>) -> Result<()> {
        let ctx = self.ctx.clone();
        ctx.scoped("uploading an injection map", || {
            self.set_static_injection_inner(field, j)
        })?
    }

    fn set_static_injection_inner(&mut self, field: usize, j: Option<&[f32]>) -> Result<()> {
        let n = self.spec.len();
        match j {
            None => self.fields[field].inj_offset = None,
            Some(j) => {
                if j.len() != n {
                    return Err(GpuError::Invalid(format!(
                        "injection map of field {field}: {} values for {n} cells",
                        j.len()
                    )));
                }
                let off = match self.fields[field].inj_offset {
                    Some(o) => o as usize,
                    None => {
                        let o = self.inj_data.len();
                        self.inj_data.resize(o + n, 0.0);
                        o
                    }
                };
                self.inj_data[off..off + n].copy_from_slice(j);
                self.fields[field].inj_offset = Some(off as u32);
                let bytes = self.inj_data.len() as u64 * 4;
                check_size(&self.ctx, "static injection maps", bytes)?;
                if self.inj_data.len() as u32 > self.inj_len {
                    self.inj = storage(
                        &self.ctx,
                        "colcos injection maps",
                        bytes,
                        wgpu::BufferUsages::empty(),
                    );
                    self.inj_len = self.inj_data.len() as u32;
                    self.bind = None;
                    self.ctx
                        .queue
                        .write_buffer(&self.inj, 0, bytemuck::cast_slice(&self.inj_data));
                } else {
                    self.ctx
                        .queue
                        .write_buffer(&self.inj, off as u64 * 4, bytemuck::cast_slice(j));
                }
            }
        }
        Ok(())
    }

    fn ensure(&mut self, which: u8, bytes: u64) {
        let buf = match which {
            0 => &mut self.plan,
            1 => &mut self.uniforms,
            _ => &mut self.deps,
        };
        if buf.size() >= bytes {
            return;
        }
        let size = bytes.next_power_of_two();
        *buf = if which == 1 {
            self.ctx.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("colcos pass uniforms"),
                size,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        } else {
            storage(
                &self.ctx,
                "colcos plan/deposits",
                size,
                wgpu::BufferUsages::empty(),
            )
        };
        self.bind = None;
    }

    fn bind_group(&mut self) -> wgpu::BindGroup {
        if let Some(b) = &self.bind {
            return b.clone();
        }
        fn whole(binding: u32, buffer: &wgpu::Buffer) -> wgpu::BindGroupEntry<'_> {
            wgpu::BindGroupEntry {
                binding,
                resource: buffer.as_entire_binding(),
            }
        }
        let b = self
            .ctx
            .device
            .create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("colcos field bind group"),
                layout: &self.pipes.layout,
                entries: &[
                    whole(0, &self.vals),
                    whole(1, &self.plan),
                    wgpu::BindGroupEntry {
                        binding: 2,
                        resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                            buffer: &self.uniforms,
                            offset: 0,
                            size: std::num::NonZeroU64::new(32),
                        }),
                    },
                    whole(3, &self.inj),
                    whole(4, &self.coef),
                    whole(5, &self.deps),
                ],
            });
        self.bind = Some(b.clone());
        b
    }

    /// Records `passes` (kinds with one plan entry per field) into one submission.
    fn run_passes(&mut self, passes: &[(Kind, Vec<PlanEntry>)]) {
        if passes.is_empty() {
            return;
        }
        let nf = self.fields.len();
        let plan: Vec<PlanEntry> = passes.iter().flat_map(|(_, e)| e.iter().copied()).collect();
        self.ensure(0, (plan.len() * 32) as u64);
        self.ensure(1, passes.len() as u64 * UNIFORM_STRIDE);
        let (nx, ny) = (self.spec.nx, self.spec.ny);
        let mut uniforms = vec![0u8; passes.len() * UNIFORM_STRIDE as usize];
        let mut shapes = Vec::with_capacity(passes.len());
        for (p, (kind, _)) in passes.iter().enumerate() {
            let (gx, gy) = match kind {
                Kind::XSolve => groups(ny, 64),
                Kind::YSolve => groups(nx, 64),
                _ => groups(nx * ny, 256),
            };
            let u = PassUniform {
                index: p as u32,
                nfields: nf as u32,
                nx: nx as u32,
                ny: ny as u32,
                groups_x: gx,
                count: 0,
                cell: self.spec.cell,
                _pad: 0,
            };
            uniforms[p * UNIFORM_STRIDE as usize..][..32].copy_from_slice(bytemuck::bytes_of(&u));
            shapes.push((gx, gy));
        }
        self.ctx
            .queue
            .write_buffer(&self.plan, 0, bytemuck::cast_slice(&plan));
        self.ctx.queue.write_buffer(&self.uniforms, 0, &uniforms);
        let bind = self.bind_group();
        let mut enc = self
            .ctx
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("colcos field step"),
            });
        {
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("colcos field step"),
                timestamp_writes: None,
            });
            for (p, (kind, _)) in passes.iter().enumerate() {
                let pipe = match kind {
                    Kind::Evaporate => &self.pipes.evaporate,
                    Kind::Explicit => &self.pipes.explicit,
                    Kind::OneSided => &self.pipes.one_sided,
                    Kind::XSolve => &self.pipes.xsolve,
                    Kind::YSolve => &self.pipes.ysolve,
                    Kind::AdvectX => &self.pipes.advect_x,
                    Kind::AdvectY => &self.pipes.advect_y,
                };
                pass.set_pipeline(pipe);
                pass.set_bind_group(0, &bind, &[(p as u64 * UNIFORM_STRIDE) as u32]);
                let (gx, gy) = shapes[p];
                pass.dispatch_workgroups(gx, gy, nf as u32);
            }
        }
        self.ctx.queue.submit([enc.finish()]);
    }

    /// Advances every field by `dt` seconds: exact evaporation and static injection, diffusion by the
    /// field's scheme, then wind; the same passes, in the same order, as [`GridField::step`].
    pub fn step(&mut self, dt: f32) -> Result<()> {
        let ctx = self.ctx.clone();
        ctx.scoped("stepping the fields", || self.step_inner(dt))?
    }

    fn step_inner(&mut self, dt: f32) -> Result<()> {
        if dt.is_nan() || dt <= 0.0 || self.fields.is_empty() {
            return Ok(());
        }
        let GridSpec { nx, ny, cell } = self.spec;
        let nf = self.fields.len();
        let coef_stride = 2 * (nx + ny);
        // Per-field decisions, as in GridField::step.
        struct Dec {
            a: f32,
            b: f32,
            diff: Option<(Kind, usize, f32)>,
            evap_first: bool,
            mean: bool,
            wind: Option<(usize, f32, f32)>,
        }
        let mut decs = Vec::with_capacity(nf);
        let mut coef_updates: Vec<(usize, Vec<f32>)> = Vec::new();
        for (fi, st) in self.fields.iter_mut().enumerate() {
            let e = st.params.evaporation as f64;
            let dtd = dt as f64;
            let (a, b) = if e.is_finite() && e > 0.0 {
                let ln_a = -dtd / e + st.decay_carry;
                let a = ln_a.exp() as f32;
                st.decay_carry = ln_a - (a as f64).ln();
                (a, (e * (1.0 - a as f64)) as f32)
            } else if e.is_finite() {
                (0.0, 0.0)
            } else {
                (1.0, dt)
            };
            let d = st.params.diffusion.max(0.0);
            let r = if d.is_finite() {
                d * dt / (cell * cell)
            } else {
                f32::INFINITY
            };
            let has_diffusion = r > 0.0 && (nx > 1 || ny > 1);
            let (mut diff, mut evap_first, mut mean) = (None, false, false);
            if !has_diffusion {
                evap_first = true;
            } else {
                match st.params.scheme {
                    DiffusionScheme::Auto if r <= EXPLICIT_MAX_R => {
                        diff = Some((Kind::Explicit, 1, r))
                    }
                    DiffusionScheme::Auto | DiffusionScheme::Implicit => {
                        if r.is_finite() {
                            diff = Some((Kind::XSolve, 1, r));
                            if st.coef_r != Some(r.to_bits()) {
                                let (mx, cx) = thomas(nx, r);
                                let (my, cy) = thomas(ny, r);
                                let mut c = mx;
                                c.extend(cx);
                                c.extend(my);
                                c.extend(cy);
                                coef_updates.push((fi, c));
                                st.coef_r = Some(r.to_bits());
                            }
                        } else {
                            evap_first = true;
                            mean = true;
                        }
                    }
                    DiffusionScheme::Explicit => {
                        let n = substeps(r, EXPLICIT_MAX_R);
                        diff = Some((Kind::Explicit, n, r / n as f32));
                    }
                    DiffusionScheme::OneSided => {
                        evap_first = true;
                        let n = substeps(r, ONE_SIDED_MAX_S);
                        diff = Some((Kind::OneSided, n, r / n as f32));
                    }
                }
            }
            let w = st.params.wind;
            let wind = if w != Vec2::ZERO && w.is_finite() {
                let cx = w.x * dt / cell;
                let cy = w.y * dt / cell;
                let n = substeps(cx.abs().max(cy.abs()), WIND_MAX_CFL);
                Some((n, cx / n as f32, cy / n as f32))
            } else {
                None
            };
            decs.push(Dec {
                a,
                b,
                diff,
                evap_first,
                mean,
                wind,
            });
        }
        for (fi, c) in coef_updates {
            self.ctx.queue.write_buffer(
                &self.coef,
                (fi * coef_stride) as u64 * 4,
                bytemuck::cast_slice(&c),
            );
        }

        // Build the passes; `slots` tracks each field's current slot as the passes flip them.
        let mut slots: Vec<u32> = self.fields.iter().map(|s| s.slot).collect();
        let inj: Vec<i32> = self
            .fields
            .iter()
            .map(|s| s.inj_offset.map_or(-1, |o| o as i32))
            .collect();
        let mut passes: Vec<(Kind, Vec<PlanEntry>)> = Vec::new();
        let mut add =
            |kind: Kind, slots: &mut Vec<u32>, make: &dyn Fn(usize) -> Option<PlanEntry>| {
                let mut any = false;
                let entries: Vec<PlanEntry> = (0..nf)
                    .map(|f| match make(f) {
                        Some(mut e) => {
                            any = true;
                            e.on = 1;
                            e.src = slots[f];
                            e.coef = (f * coef_stride) as u32;
                            if kind.flips() {
                                slots[f] ^= 1;
                            }
                            e
                        }
                        None => PlanEntry::default(),
                    })
                    .collect();
                if any {
                    passes.push((kind, entries));
                }
            };
        add(Kind::Evaporate, &mut slots, &|f| {
            let d = &decs[f];
            // Without a map and with a = 1 the CPU leaves the values as they are (no flush either).
            (d.evap_first && (inj[f] >= 0 || d.a != 1.0)).then_some(PlanEntry {
                inj: inj[f],
                a: d.a,
                b: d.b,
                ..Default::default()
            })
        });
        let max_sub = decs
            .iter()
            .filter_map(|d| d.diff.map(|x| x.1))
            .max()
            .unwrap_or(0);
        for k in 0..max_sub {
            add(Kind::Explicit, &mut slots, &|f| match decs[f].diff {
                Some((Kind::Explicit, n, r)) if k < n => {
                    let (a, b, i) = if k == 0 {
                        (decs[f].a, decs[f].b, inj[f])
                    } else {
                        (1.0, 0.0, -1)
                    };
                    Some(PlanEntry {
                        inj: i,
                        a,
                        b,
                        r,
                        ..Default::default()
                    })
                }
                _ => None,
            });
        }
        for k in 0..max_sub {
            add(Kind::OneSided, &mut slots, &|f| match decs[f].diff {
                Some((Kind::OneSided, n, s)) if k < n => Some(PlanEntry {
                    inj: -1,
                    r: s,
                    ..Default::default()
                }),
                _ => None,
            });
        }
        add(Kind::XSolve, &mut slots, &|f| match decs[f].diff {
            Some((Kind::XSolve, _, r)) => Some(PlanEntry {
                inj: inj[f],
                a: decs[f].a,
                b: decs[f].b,
                r,
                ..Default::default()
            }),
            _ => None,
        });
        if ny > 1 {
            add(Kind::YSolve, &mut slots, &|f| match decs[f].diff {
                Some((Kind::XSolve, _, r)) => Some(PlanEntry {
                    inj: -1,
                    r,
                    ..Default::default()
                }),
                _ => None,
            });
        }
        let mut wind_passes: Vec<(Kind, Vec<PlanEntry>)> = Vec::new();
        let any_mean = decs.iter().any(|d| d.mean);
        if any_mean {
            // Infinite diffusion (uniform at the mean): finish the first passes, average on the CPU.
            self.run_passes(&passes);
            passes.clear();
            for (f, d) in decs.iter().enumerate() {
                if d.mean {
                    self.fields[f].slot = slots[f];
                    let v = self.read_field(f)?;
                    let mean = (v.iter().map(|&v| v as f64).sum::<f64>() / v.len() as f64) as f32;
                    self.write_field(f, &vec![mean; v.len()])?;
                }
            }
        }
        let max_wind = decs
            .iter()
            .filter_map(|d| d.wind.map(|w| w.0))
            .max()
            .unwrap_or(0);
        {
            let mut add_w =
                |kind: Kind, slots: &mut Vec<u32>, make: &dyn Fn(usize) -> Option<PlanEntry>| {
                    let mut any = false;
                    let entries: Vec<PlanEntry> = (0..nf)
                        .map(|f| match make(f) {
                            Some(mut e) => {
                                any = true;
                                e.on = 1;
                                e.src = slots[f];
                                slots[f] ^= 1;
                                e
                            }
                            None => PlanEntry::default(),
                        })
                        .collect();
                    if any {
                        wind_passes.push((kind, entries));
                    }
                };
            for k in 0..max_wind {
                add_w(Kind::AdvectX, &mut slots, &|f| match decs[f].wind {
                    Some((n, cx, _)) if k < n && cx != 0.0 && nx > 1 => Some(PlanEntry {
                        inj: -1,
                        c: cx,
                        ..Default::default()
                    }),
                    _ => None,
                });
                add_w(Kind::AdvectY, &mut slots, &|f| match decs[f].wind {
                    Some((n, _, cy)) if k < n && cy != 0.0 && ny > 1 => Some(PlanEntry {
                        inj: -1,
                        c: cy,
                        ..Default::default()
                    }),
                    _ => None,
                });
            }
        }
        passes.extend(wind_passes);
        self.run_passes(&passes);
        for (st, s) in self.fields.iter_mut().zip(slots) {
            st.slot = s;
        }
        Ok(())
    }

    /// Adds trail deposits, in order (deposits on one field are summed in the order given, as a
    /// sequence of [`GridField::deposit_segment`] calls would).
    pub fn deposit(&mut self, deposits: &[Deposit]) -> Result<()> {
        let ctx = self.ctx.clone();
        ctx.scoped("depositing trails", || self.deposit_inner(deposits))?
    }

    fn deposit_inner(&mut self, deposits: &[Deposit]) -> Result<()> {
        let GridSpec { nx, ny, cell } = self.spec;
        let mut per_field_count = vec![0usize; self.fields.len()];
        let mut rounds: Vec<Vec<DepRecord>> = Vec::new();
        for d in deposits {
            if d.field >= self.fields.len() {
                return Err(GpuError::Invalid(format!(
                    "deposit on field {} of {}",
                    d.field,
                    self.fields.len()
                )));
            }
            let support = d.kernel.support();
            if support.is_nan() || support < 0.0 || !d.a.is_finite() || !d.b.is_finite() {
                continue;
            }
            let (a, b) = (d.a, d.b);
            let (i0, i1) = cell_range(cell, a.x.min(b.x) - support, a.x.max(b.x) + support, nx);
            let (j0, j1) = cell_range(cell, a.y.min(b.y) - support, a.y.max(b.y) + support, ny);
            if i1 <= i0 || j1 <= j0 {
                continue;
            }
            let ab = b - a;
            let (kind, param) = match d.kernel {
                Kernel::Disc { radius } => (0, radius),
                Kernel::Cone { radius } => (1, radius),
                Kernel::Gaussian { sigma } => (2, sigma),
            };
            let rec = DepRecord {
                field: d.field as u32,
                slot: self.fields[d.field].slot,
                i0: i0 as u32,
                j0: j0 as u32,
                w: (i1 - i0) as u32,
                h: (j1 - j0) as u32,
                kind,
                _pad: 0,
                ax: a.x,
                ay: a.y,
                abx: ab.x,
                aby: ab.y,
                len2: ab.length_squared(),
                support,
                param,
                amount: d.amount,
            };
            let r = per_field_count[d.field];
            per_field_count[d.field] += 1;
            if rounds.len() <= r {
                rounds.push(Vec::new());
            }
            rounds[r].push(rec);
        }
        if rounds.is_empty() {
            return Ok(());
        }
        if rounds.iter().any(|r| r.len() > MAX_GROUPS as usize) {
            return Err(GpuError::Invalid(format!(
                "more than {MAX_GROUPS} fields with a deposit in one call: split the call"
            )));
        }
        let recs: Vec<DepRecord> = rounds.iter().flatten().copied().collect();
        self.ensure(2, (recs.len() * std::mem::size_of::<DepRecord>()) as u64);
        self.ensure(1, rounds.len() as u64 * UNIFORM_STRIDE);
        let mut uniforms = vec![0u8; rounds.len() * UNIFORM_STRIDE as usize];
        let mut shapes = Vec::new();
        let mut first = 0u32;
        for (k, round) in rounds.iter().enumerate() {
            let cells = round
                .iter()
                .map(|r| (r.w * r.h) as usize)
                .max()
                .unwrap_or(0);
            let (gx, gy) = groups(cells, 256);
            let u = PassUniform {
                index: first,
                nfields: self.fields.len() as u32,
                nx: nx as u32,
                ny: ny as u32,
                groups_x: gx,
                count: round.len() as u32,
                cell,
                _pad: 0,
            };
            uniforms[k * UNIFORM_STRIDE as usize..][..32].copy_from_slice(bytemuck::bytes_of(&u));
            shapes.push((gx, gy, round.len() as u32));
            first += round.len() as u32;
        }
        self.ctx
            .queue
            .write_buffer(&self.deps, 0, bytemuck::cast_slice(&recs));
        self.ctx.queue.write_buffer(&self.uniforms, 0, &uniforms);
        let bind = self.bind_group();
        let mut enc = self
            .ctx
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("colcos deposits"),
            });
        {
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("colcos deposits"),
                timestamp_writes: None,
            });
            pass.set_pipeline(&self.pipes.deposit);
            for (k, &(gx, gy, count)) in shapes.iter().enumerate() {
                pass.set_bind_group(0, &bind, &[(k as u64 * UNIFORM_STRIDE) as u32]);
                pass.dispatch_workgroups(gx, gy, count);
            }
        }
        self.ctx.queue.submit([enc.finish()]);
        Ok(())
    }
}
