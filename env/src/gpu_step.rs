//! A step of a batch whose grid pheromones live on the GPU, in three stages: every world moves on the
//! CPU (chunk by chunk, each chunk's rapier host stepping its worlds together), the GPU stage does
//! every world's field work at once, and every world reads its sensors' sums into observations and
//! hands out rewards on the CPU. The chunks are those of `batch_step`, so results do not depend on
//! the number of threads.
use crate::batch_step::Chunks;
use crate::error::Result;
use crate::gpu_stage::GpuStage;
use crate::outputs::OutSlices;
use crate::world_slot::WorldSlot;
use crate::world_step::{
    Begun, Ctx, Evaluation, WorldMut, begin_world, conclude_world, finish_motion,
};
use colcos_sim::behaviour::WheelCommand;
use rayon::prelude::*;
use std::time::Instant;

/// One step of every world with the fields on the GPU, on the current rayon pool.
#[allow(clippy::too_many_arguments)]
pub(crate) fn step_batch_gpu(
    ctx: &Ctx,
    slots: &mut [WorldSlot],
    chunks: &mut Chunks,
    stage: &mut GpuStage,
    commands: &[WheelCommand],
    rates: &[f32],
    mut buffers: OutSlices,
) -> Result<()> {
    let c = chunks.size();
    let n = ctx.task.agents().len();
    let per_world = n * ctx.deposits;
    let t0 = Instant::now();
    // 1. Motion: decisions, shield, physics, tracking, the Gaussian fields' clocks, trail segments.
    chunks
        .par_iter_mut(slots)
        .zip(commands.par_chunks(c * n))
        .zip(buffers.reborrow().par_chunks(c))
        .zip(stage.begun.par_chunks_mut(c))
        .enumerate()
        .try_for_each(
            |(k, ((((slots, mut host), commands), mut buffers), begun))| {
                let mut result = Ok(());
                for (i, slot) in slots.iter_mut().enumerate() {
                    let w = k * c + i;
                    let cmds = &commands[i * n..(i + 1) * n];
                    let lay = &rates[w * per_world..(w + 1) * per_world];
                    let mut out = buffers.world(i);
                    let world = WorldMut::in_chunk(w, i, slot, &mut out, host.as_deref_mut());
                    begun[i] = match begin_world(ctx, world, (cmds, lay)) {
                        Ok(b) => b,
                        Err(err) => {
                            if result.is_ok() {
                                result = Err(err);
                            }
                            Begun::Reset
                        }
                    };
                }
                if let Some(host) = host.as_deref_mut() {
                    host.step(ctx.scenario.spec.dt);
                    for (slot, &b) in slots.iter_mut().zip(begun.iter()) {
                        finish_motion(slot, b, Some(&mut *host));
                    }
                }
                result
            },
        )?;
    let t1 = Instant::now();
    // 2. Fields, deposits and sensing of every world on the GPU.
    stage.run(slots, ctx.scenario.spec.dt)?;
    let run_end = Instant::now();
    if ctx.writer.patch.is_some() || matches!(ctx.evaluation, Evaluation::Deferred) {
        // Patches and a task written in Python read the fields on the CPU.
        stage.sync(slots)?;
    }
    // 3. Observations from the sums, rewards, outputs.
    let concluded = chunks
        .par_iter_mut(slots)
        .zip(buffers.par_chunks(c))
        .zip(stage.begun.par_chunks(c))
        .enumerate()
        .try_for_each(|(k, (((slots, mut host), mut buffers), begun))| {
            let mut result = Ok(());
            for (i, slot) in slots.iter_mut().enumerate().rev() {
                if begun[i] == Begun::Reset {
                    continue;
                }
                let w = k * c + i;
                slot.world.sense_from_sums(stage.sums_of(w));
                let mut out = buffers.world(i);
                let world = WorldMut::in_chunk(w, i, slot, &mut out, host.as_deref_mut());
                let done = conclude_world(ctx, world);
                if result.is_ok() {
                    result = done;
                }
            }
            result
        });
    let t3 = Instant::now();
    // The stage times its own four parts; its sync, where there is one, counts with observations.
    stage.seconds[0] += (t1 - t0).as_secs_f64();
    stage.seconds[5] += (t3 - run_end).as_secs_f64();
    concluded
}
