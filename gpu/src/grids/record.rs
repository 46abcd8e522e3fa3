//! Recording passes: the per-pass uniforms, the plan and deposit buffers, the bind group, and the one
//! function that turns a list of dispatches into a submission.
use super::GpuGrids;
use crate::program::shader_struct;
use crate::storage;

/// Bytes between two dispatch uniforms (the dynamic-offset alignment wgpu guarantees to accept).
pub(super) const UNIFORM_STRIDE: u64 = 256;
/// Most workgroups along one dispatch dimension.
pub(super) const MAX_GROUPS: u32 = 65535;

shader_struct! {
    /// What one field does in one pass (`on = 0`: nothing), as the shader reads it.
    pub(super) struct PlanEntry as PF {
        pub(super) on: u32,
        pub(super) src: u32,
        /// Offset of the field's static injection map in `inj`, or -1.
        pub(super) inj: i32,
        /// Offset of the field's Thomas coefficients in `coef`.
        pub(super) coef: u32,
        pub(super) a: f32,
        pub(super) b: f32,
        pub(super) r: f32,
        pub(super) c: f32,
    }
}

shader_struct! {
    /// The uniform of one dispatch, at its own [`UNIFORM_STRIDE`] offset.
    pub(super) struct PassUniform as Pass {
        /// Row of the plan (`plan[index * nfields + f]`) or first deposit of a round.
        pub(super) index: u32,
        pub(super) nfields: u32,
        pub(super) nx: u32,
        pub(super) ny: u32,
        /// Workgroups along x of the dispatch (linear ids fold x and y).
        pub(super) groups_x: u32,
        /// Deposits in the round.
        pub(super) count: u32,
        pub(super) cell: f32,
        pub(super) _pad: u32,
    }
}

// The shader's structs, byte for byte.
const _: () = assert!(std::mem::size_of::<PlanEntry>() == 32);
const _: () = assert!(std::mem::size_of::<PassUniform>() == 32);

/// The kinds of pass, one shader entry point each.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Kind {
    Evaporate,
    Explicit,
    OneSided,
    XSolve,
    YSolve,
    AdvectX,
    AdvectY,
    Deposit,
}

impl Kind {
    /// Whether a step pass writes the other slot (ping-pong) rather than in place.
    pub(super) fn flips(self) -> bool {
        self != Kind::Evaporate
    }
}

/// One dispatch: the pass kind, its uniform and its workgroup counts.
pub(super) struct Dispatch {
    pub(super) kind: Kind,
    pub(super) uniform: PassUniform,
    pub(super) groups: [u32; 3],
}

/// The buffers that grow on demand.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(super) enum Grown {
    Plan,
    Uniforms,
    Deposits,
}

/// Workgroup counts (x, y) covering `items` with `per` items per group, folded under the 65,535 limit.
pub(super) fn groups(items: usize, per: usize) -> (u32, u32) {
    let g = items.div_ceil(per).max(1) as u64;
    let gx = g.min(MAX_GROUPS as u64);
    (gx as u32, g.div_ceil(gx) as u32)
}

impl GpuGrids {
    /// Makes `which` hold at least `bytes` (a new, larger buffer drops the bind group).
    pub(super) fn ensure(&mut self, which: Grown, bytes: u64) {
        let buf = match which {
            Grown::Plan => &mut self.plan,
            Grown::Uniforms => &mut self.uniforms,
            Grown::Deposits => &mut self.deps,
        };
        if buf.size() >= bytes {
            return;
        }
        let size = bytes.next_power_of_two();
        *buf = if which == Grown::Uniforms {
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

    /// Records `dispatches` in order into one compute pass, each with its uniform, and submits it.
    pub(super) fn record(&mut self, label: &str, dispatches: &[Dispatch]) {
        if dispatches.is_empty() {
            return;
        }
        self.ensure(Grown::Uniforms, dispatches.len() as u64 * UNIFORM_STRIDE);
        let mut uniforms = vec![0u8; dispatches.len() * UNIFORM_STRIDE as usize];
        for (k, d) in dispatches.iter().enumerate() {
            uniforms[k * UNIFORM_STRIDE as usize..][..std::mem::size_of::<PassUniform>()]
                .copy_from_slice(bytemuck::bytes_of(&d.uniform));
        }
        self.ctx.queue.write_buffer(&self.uniforms, 0, &uniforms);
        let bind = self.bind_group();
        let mut enc = self
            .ctx
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some(label) });
        {
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some(label),
                timestamp_writes: None,
            });
            for (k, d) in dispatches.iter().enumerate() {
                pass.set_pipeline(self.pipes.pipeline(d.kind));
                pass.set_bind_group(0, &bind, &[(k as u64 * UNIFORM_STRIDE) as u32]);
                let [gx, gy, gz] = d.groups;
                pass.dispatch_workgroups(gx, gy, gz);
            }
        }
        self.ctx.queue.submit([enc.finish()]);
    }

    /// Records step passes (kinds with one plan entry per field) into one submission.
    /// `entries` holds one entry per field for each pass of `kinds`, pass after pass.
    pub(super) fn run_passes(&mut self, kinds: &[Kind], entries: &[PlanEntry]) {
        if kinds.is_empty() {
            return;
        }
        let nf = self.fields.len();
        self.ensure(Grown::Plan, std::mem::size_of_val(entries) as u64);
        self.ctx
            .queue
            .write_buffer(&self.plan, 0, bytemuck::cast_slice(entries));
        let (nx, ny) = (self.spec.nx, self.spec.ny);
        let dispatches: Vec<Dispatch> = kinds
            .iter()
            .enumerate()
            .map(|(p, &kind)| {
                let (gx, gy) = match kind {
                    // 64 lines a workgroup: `LINES` of field.wgsl's solves.
                    Kind::XSolve => groups(ny, 64),
                    Kind::YSolve => groups(nx, 64),
                    _ => groups(nx * ny, 256),
                };
                Dispatch {
                    kind,
                    uniform: PassUniform {
                        index: p as u32,
                        nfields: nf as u32,
                        nx: nx as u32,
                        ny: ny as u32,
                        groups_x: gx,
                        count: 0,
                        cell: self.spec.cell,
                        _pad: 0,
                    },
                    groups: [gx, gy, nf as u32],
                }
            })
            .collect();
        self.record("colcos field step", &dispatches);
    }
}
