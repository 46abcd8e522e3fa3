//! The field shader, compiled once per device into one compute pipeline per pass kind.
use super::deposit::DepRecord;
use super::record::{Kind, PassUniform, PlanEntry};
use crate::program::{ComputeProgram, READ, WRITE};
use crate::{GpuContext, Result};
use std::sync::Arc;

/// The field shader's pipelines and their layout: compiled once per device (see
/// [`FieldPipelines::get`]) and shared by every batch on it, so that making a batch (one per world, for a
/// vector env) costs only its buffers.
pub(crate) struct FieldPipelines {
    pub(super) layout: wgpu::BindGroupLayout,
    evaporate: wgpu::ComputePipeline,
    explicit: wgpu::ComputePipeline,
    one_sided: wgpu::ComputePipeline,
    xsolve: wgpu::ComputePipeline,
    ysolve: wgpu::ComputePipeline,
    advect_x: wgpu::ComputePipeline,
    advect_y: wgpu::ComputePipeline,
    deposit: wgpu::ComputePipeline,
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
    let structs = [PlanEntry::WGSL, PassUniform::WGSL, DepRecord::WGSL].concat();
    include_str!("../field.wgsl")
        .replace("//STRUCTS//", &structs)
        .replace("//KEXP//", &kexp)
}

impl FieldPipelines {
    /// The context's pipelines, compiled on first use.
    pub(super) fn get(ctx: &GpuContext) -> Result<Arc<FieldPipelines>> {
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
        let dynamic_uniform = (wgpu::BufferBindingType::Uniform, true);
        let program = ComputeProgram::new(
            device,
            "field",
            field_source(ctx.f64),
            &[WRITE, READ, dynamic_uniform, READ, READ, READ],
        );
        let pipe = |name: &str| program.pipeline(device, name);
        FieldPipelines {
            evaporate: pipe("evaporate"),
            explicit: pipe("explicit_step"),
            one_sided: pipe("one_sided"),
            xsolve: pipe("xsolve"),
            ysolve: pipe("ysolve"),
            advect_x: pipe("advect_x"),
            advect_y: pipe("advect_y"),
            deposit: pipe("deposit"),
            layout: program.into_layout(),
        }
    }

    /// The pipeline of a pass kind.
    pub(super) fn pipeline(&self, kind: Kind) -> &wgpu::ComputePipeline {
        match kind {
            Kind::Evaporate => &self.evaporate,
            Kind::Explicit => &self.explicit,
            Kind::OneSided => &self.one_sided,
            Kind::XSolve => &self.xsolve,
            Kind::YSolve => &self.ysolve,
            Kind::AdvectX => &self.advect_x,
            Kind::AdvectY => &self.advect_y,
            Kind::Deposit => &self.deposit,
        }
    }
}
