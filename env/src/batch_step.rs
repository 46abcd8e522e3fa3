//! A step of many worlds, in fixed chunks of worlds stepped one after the other by one task. The
//! worlds of a chunk that use rapier take their contact steps together in the chunk's
//! [`RapierHost`]: one rapier step for the chunk instead of one per world, each world moving as it
//! would alone while none of its robots touches two things at once (see
//! `colcos_sim::robot::RapierHost`). Chunks are fixed by world index and count, so results do not
//! depend on the number of threads.
use crate::error::Result;
use crate::outputs::OutSlices;
use crate::world_slot::WorldSlot;
use crate::world_step::{Begun, Ctx, WorldMut, begin_world, conclude_world, finish_world};
use colcos_sim::behaviour::WheelCommand;
use colcos_sim::robot::{MAX_HOSTED_ARENAS, PhysicsBackend, RapierHost};
use colcos_sim::scenario::Scenario;
use rayon::prelude::*;

/// Fewest chunks a batch is cut into where worlds share hosts, so that threads share the work
/// evenly (31 worlds a chunk from 992 worlds on).
const MIN_CHUNKS: usize = 32;
/// Most robots a world may have to join a host: larger worlds always have contacts, so their
/// steps go through rapier anyway and gain nothing from sharing it.
const HOST_MAX_ROBOTS: usize = 64;

/// How a batch is cut into chunks, and each chunk's rapier host (`None` where its worlds step
/// alone: the disc solver, large worlds, batches too small to share).
pub(crate) struct Chunks {
    size: usize,
    hosts: Vec<Option<RapierHost>>,
}

impl Chunks {
    /// The chunks of a batch of `slots` of `scenario`.
    pub(crate) fn new(scenario: &Scenario, slots: &[WorldSlot]) -> Self {
        let worlds = slots.len();
        let size = (worlds / MIN_CHUNKS).clamp(1, MAX_HOSTED_ARENAS);
        let hosted = size > 1
            && scenario.spec.physics == PhysicsBackend::Rapier
            && scenario.robot_count() <= HOST_MAX_ROBOTS;
        let size = if hosted { size } else { 1 };
        let hosts = (0..worlds.div_ceil(size))
            .map(|_| {
                let world = &slots.first()?.world;
                hosted.then(|| RapierHost::new(world.arena(), world.obstacles(), size))
            })
            .collect();
        Chunks { size, hosts }
    }

    /// Worlds per chunk (the last may have fewer).
    pub(crate) fn size(&self) -> usize {
        self.size
    }

    /// Each chunk of `slots` with its host.
    pub(crate) fn par_iter_mut<'a>(
        &'a mut self,
        slots: &'a mut [WorldSlot],
    ) -> impl IndexedParallelIterator<Item = (&'a mut [WorldSlot], Option<&'a mut RapierHost>)>
    {
        slots
            .par_chunks_mut(self.size)
            .zip(self.hosts.par_iter_mut().map(Option::as_mut))
    }

    /// Moves every world's rapier steps into its chunk's host.
    pub(crate) fn attach_all(&mut self, slots: &mut [WorldSlot]) {
        self.par_iter_mut(slots).for_each(|(slots, host)| {
            if let Some(host) = host {
                for (i, slot) in slots.iter_mut().enumerate() {
                    slot.world.attach_physics(host, i);
                }
            }
        });
    }
}

/// One step of every world, chunk by chunk on the current rayon pool.
pub(crate) fn step_batch(
    ctx: &Ctx,
    slots: &mut [WorldSlot],
    chunks: &mut Chunks,
    commands: &[WheelCommand],
    rates: &[f32],
    buffers: OutSlices,
) -> Result<()> {
    let c = chunks.size();
    let n = ctx.task.agents().len();
    chunks
        .par_iter_mut(slots)
        .zip(commands.par_chunks(c * n))
        .zip(buffers.par_chunks(c))
        .enumerate()
        .try_for_each(|(k, (((slots, host), commands), mut buffers))| {
            step_chunk(ctx, k * c, slots, host, commands, rates, &mut buffers)
        })
}

/// One step of the worlds of a chunk (the first is world `first`; `commands` are the chunk's,
/// `rates` the whole batch's): each begins its step, the host steps, each finishes. A world whose
/// step fails leaves the others' steps whole; an error met is returned.
fn step_chunk(
    ctx: &Ctx,
    first: usize,
    slots: &mut [WorldSlot],
    mut host: Option<&mut RapierHost>,
    commands: &[WheelCommand],
    rates: &[f32],
    buffers: &mut OutSlices,
) -> Result<()> {
    let n = ctx.task.agents().len();
    let per_world = n * ctx.deposits;
    let mut begun = [Begun::Reset; MAX_HOSTED_ARENAS];
    let mut result = Ok(());
    for (i, slot) in slots.iter_mut().enumerate() {
        let cmds = &commands[i * n..(i + 1) * n];
        let w = first + i;
        let lay = &rates[w * per_world..(w + 1) * per_world];
        let mut out = buffers.world(i);
        let world = WorldMut::in_chunk(w, i, slot, &mut out, host.as_deref_mut());
        match begin_world(ctx, world, (cmds, lay)) {
            Ok(b) => begun[i] = b,
            Err(err) if result.is_ok() => result = Err(err),
            Err(_) => {}
        }
    }
    if let Some(host) = host.as_deref_mut() {
        host.step(ctx.scenario.spec.dt);
    }
    // Last begun, first finished: those worlds' data is still in cache (worlds are independent, so
    // the order changes nothing else; 7-10 % more steps a second at 1,024 worlds).
    for (i, slot) in slots.iter_mut().enumerate().rev() {
        let mut out = buffers.world(i);
        let world = WorldMut::in_chunk(first + i, i, slot, &mut out, host.as_deref_mut());
        let finished = finish_world(ctx, world, begun[i]);
        if result.is_ok() {
            result = finished;
        }
    }
    result
}

/// The end of every world's step that awaits it (a task written in Python: `ctx.evaluation` gives
/// the rewards and terminations), chunk by chunk on the current rayon pool.
pub(crate) fn conclude_batch(
    ctx: &Ctx,
    slots: &mut [WorldSlot],
    chunks: &mut Chunks,
    buffers: OutSlices,
) -> Result<()> {
    let c = chunks.size();
    chunks
        .par_iter_mut(slots)
        .zip(buffers.par_chunks(c))
        .enumerate()
        .try_for_each(|(k, ((slots, mut host), mut buffers))| {
            let mut result = Ok(());
            for (i, slot) in slots.iter_mut().enumerate().rev() {
                if !slot.awaiting {
                    continue;
                }
                let mut out = buffers.world(i);
                let world = WorldMut::in_chunk(k * c + i, i, slot, &mut out, host.as_deref_mut());
                let concluded = conclude_world(ctx, world);
                if result.is_ok() {
                    result = concluded;
                }
            }
            result
        })
}
