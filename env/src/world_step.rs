//! One world's step of the batch: the agents' commands pass the safety shield, the world steps (its
//! other robots deciding with their own behaviours), the task hands out rewards and ends episodes,
//! and the outputs are written.
use crate::backend::EnvBackend;
use crate::config::AutoresetMode;
use crate::episode::StepEnd;
use crate::error::Result;
use crate::outputs::{OutSlices, Writer};
use crate::task::Task;
use crate::world_slot::WorldSlot;
use colcos_sim::robot::RapierHost;
use colcos_sim::scenario::Scenario;
use colcos_sim::shield::{Intervention, Shield};

/// One world's agents' commands `[N]` and deposit rate fractions `[N, D]`.
pub(crate) type AgentActions<'a> = (&'a [colcos_sim::behaviour::WheelCommand], &'a [f32]);

/// Everything a world's step needs besides its own slot and buffers.
pub(crate) struct Ctx<'a> {
    pub(crate) task: &'a dyn Task,
    pub(crate) scenario: &'a Scenario,
    pub(crate) backend: &'a EnvBackend,
    pub(crate) mode: AutoresetMode,
    /// How the outputs are written; its `max_cycles` is the episode length.
    pub(crate) writer: Writer,
    pub(crate) shield: Option<Shield>,
    /// Deposit actions per agent.
    pub(crate) deposits: usize,
    /// How a step's evaluation is made (see [`Evaluation`]).
    pub(crate) evaluation: Evaluation<'a>,
}

/// Who hands out rewards and terminations at the end of a step.
#[derive(Clone, Copy)]
pub(crate) enum Evaluation<'a> {
    /// The Rust task, right after the world's step.
    Task,
    /// Later, by [`conclude_world`] with values given for the whole batch (`[E, N]`): a task
    /// written in Python, whose hooks run once on every world's state in between.
    Deferred,
    Given {
        rewards: &'a [f32],
        terminated: &'a [bool],
    },
}

/// World `w` as a step reaches it: its slot, its output slices and, for a world in a rapier host,
/// the host and the world's slot in it.
pub(crate) struct WorldMut<'a, 'o> {
    pub(crate) w: usize,
    pub(crate) slot: &'a mut WorldSlot,
    pub(crate) out: &'a mut OutSlices<'o>,
    pub(crate) host: Option<(&'a mut RapierHost, usize)>,
}

impl<'a, 'o> WorldMut<'a, 'o> {
    /// World `w`, the `i`-th of its chunk, whose rapier steps are in the chunk's `host` if it has one.
    pub(crate) fn in_chunk(
        w: usize,
        i: usize,
        slot: &'a mut WorldSlot,
        out: &'a mut OutSlices<'o>,
        host: Option<&'a mut RapierHost>,
    ) -> Self {
        let host = host.map(|h| (h, i));
        WorldMut { w, slot, out, host }
    }
}

/// How far [`begin_world`] took a world's step.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Begun {
    /// The world only reset (next-step autoreset): its outputs are written.
    Reset,
    /// The world stepped alone.
    Stepped,
    /// The world waits for its rapier host's step.
    InHost,
}

/// One whole step of world `w`, which steps alone.
pub(crate) fn step_world(
    ctx: &Ctx,
    w: usize,
    slot: &mut WorldSlot,
    actions: AgentActions,
    out: &mut OutSlices,
) -> Result<()> {
    let begun = begin_world(ctx, WorldMut::in_chunk(w, 0, slot, out, None), actions)?;
    finish_world(ctx, WorldMut::in_chunk(w, 0, slot, out, None), begun)
}

/// The first half of a world's step: autoreset, scripted robots, shield, and the motion, which
/// for a world in a rapier host waits for the host's step.
pub(crate) fn begin_world(
    ctx: &Ctx,
    world: WorldMut,
    (cmds, rates): AgentActions,
) -> Result<Begun> {
    let agents = ctx.task.agents();
    let (slot, out) = (&mut *world.slot, &mut *world.out);
    out.final_mask[0] = false;
    out.shield.fill(0);
    if slot.episode.done {
        // Next-step autoreset: this step only resets the world.
        out.rewards.fill(0.0);
        out.terminated.fill(false);
        out.truncated.fill(false);
        next_episode(ctx, world)?;
        return Ok(Begun::Reset);
    }
    let poses = slot.world.poses();
    for (((&i, cmd), &term), flags) in agents
        .iter()
        .zip(cmds)
        .zip(&slot.episode.terminated)
        .zip(out.shield.iter_mut())
    {
        slot.overrides[i] = Some(if term {
            colcos_sim::behaviour::WheelCommand::STOP
        } else if let Some(shield) = &ctx.shield {
            let (cmd, intervention) = shield.apply_facing(&poses[i], slot.world.forward(i), *cmd);
            *flags = shield_bits(intervention);
            cmd
        } else {
            *cmd
        });
    }
    let d = ctx.deposits;
    if d > 0 {
        for (k, (&i, &term)) in agents.iter().zip(&slot.episode.terminated).enumerate() {
            // A terminated agent is stopped and lays nothing.
            let lay = rates[k * d..(k + 1) * d].iter();
            slot.world
                .set_deposit_actions(i, lay.map(|&f| if term { 0.0 } else { f }));
        }
    }
    Ok(match world.host {
        Some((host, _)) => {
            slot.world.begin_step_in(&slot.overrides, host);
            Begun::InHost
        }
        None => {
            slot.world.step_with_overrides(&slot.overrides);
            Begun::Stepped
        }
    })
}

/// The second half of a world's step, after its host's step: rewards, ends of episodes, outputs.
pub(crate) fn finish_world(ctx: &Ctx, mut world: WorldMut, begun: Begun) -> Result<()> {
    let host = world.host.as_mut().map(|(h, _)| &mut **h);
    if !finish_motion(world.slot, begun, host) {
        return Ok(());
    }
    conclude_world(ctx, world)
}

/// A world's motion finished after its host's step (nothing to do for a world that stepped alone);
/// false for a world that only reset.
pub(crate) fn finish_motion(
    slot: &mut WorldSlot,
    begun: Begun,
    host: Option<&mut RapierHost>,
) -> bool {
    match (begun, host) {
        (Begun::Reset, _) => return false,
        (Begun::InHost, Some(host)) => slot.world.finish_step_in(host),
        _ => {}
    }
    true
}

/// The end of a world's step once it has moved and sensed: rewards, ends of episodes, outputs, and a
/// same-step autoreset; or, where the evaluation is deferred (a task written in Python), nothing
/// until it is given.
pub(crate) fn conclude_world(ctx: &Ctx, world: WorldMut) -> Result<()> {
    let (w, slot, out) = (world.w, &mut *world.slot, &mut *world.out);
    slot.awaiting = matches!(ctx.evaluation, Evaluation::Deferred);
    if slot.awaiting {
        return Ok(());
    }
    let max_cycles = ctx.writer.max_cycles;
    let agent_out = out.agent_out();
    let done = match ctx.evaluation {
        Evaluation::Given {
            rewards,
            terminated,
        } => {
            let n = ctx.task.agents().len();
            let part = w * n..(w + 1) * n;
            (slot.episode).finish_given(
                &rewards[part.clone()],
                &terminated[part],
                max_cycles,
                StepEnd::Stepped,
                agent_out,
            )
        }
        _ => slot.episode.finish_step(
            ctx.task,
            &slot.world,
            max_cycles,
            StepEnd::Stepped,
            agent_out,
        ),
    };
    write_world(ctx, slot, out);
    if done && ctx.mode == AutoresetMode::SameStep {
        out.final_obs.copy_from_slice(out.obs);
        out.final_mask[0] = true;
        next_episode(ctx, world)?;
    }
    Ok(())
}

/// Replaces the world by its next episode (in its rapier host's slot, if any) and writes its outputs.
fn next_episode(ctx: &Ctx, world: WorldMut) -> Result<()> {
    let WorldMut { w, slot, out, host } = world;
    *slot = WorldSlot::build(
        ctx.scenario,
        ctx.task,
        ctx.backend,
        w,
        slot.episode.index + 1,
        host,
    )?;
    write_world(ctx, slot, out);
    Ok(())
}

fn write_world(ctx: &Ctx, slot: &WorldSlot, out: &mut OutSlices) {
    (ctx.writer).write(ctx.task, &slot.world, &slot.episode, out);
}

/// A shield intervention as the bits of [`VecEnv::shield_flags`].
pub fn shield_bits(i: Intervention) -> u8 {
    i.capped as u8 | (i.walled as u8) << 1
}
