//! The output buffers of every environment of a task, the batch's worlds and a plant's arena alike:
//! observations, rewards, terminations, truncations, the global state, screen patches, final
//! observations and the shield's flags, `[E, N, ...]` row-major, allocated once and overwritten in
//! place, so a binding may hand out views of them for the environment's lifetime.
//!
//! "Add an output" is done here: a field of [`Outputs`], its slice in [`OutSlices`], its pointer in
//! [`BufferPtrs`], and what [`Writer::write`] puts in it.
use crate::config::PatchConfig;
use crate::episode::{AgentOut, Episode};
use crate::spaces::EnvSpec;
use crate::task::Task;
use crate::world_output::{write_patch, write_state, write_task_obs};
use colcos_sim::world::ArenaView;
use rayon::prelude::*;

/// Per-world lengths of the buffers: agents, observation values, state values, patch bytes. The
/// state and the patch keep one element per world where disabled, so that every buffer splits into
/// one part per world.
#[derive(Clone, Copy, Debug)]
pub struct Lengths {
    pub agents: usize,
    pub obs: usize,
    pub state: usize,
    pub patch: usize,
}

/// The output buffers of `E` worlds of `N` agents.
pub struct Outputs {
    worlds: usize,
    len: Lengths,
    has_state: bool,
    has_patch: bool,
    obs: Vec<f32>,
    rewards: Vec<f32>,
    terminated: Vec<bool>,
    truncated: Vec<bool>,
    state: Vec<f32>,
    patch: Vec<u8>,
    final_obs: Vec<f32>,
    final_mask: Vec<bool>,
    shield: Vec<u8>,
}

impl Outputs {
    /// Zeroed buffers for the spaces of `spec` (`spec.num_envs` worlds).
    pub fn new(spec: &EnvSpec) -> Self {
        let (e, n) = (spec.num_envs, spec.num_agents);
        let state = spec.state.as_ref().map_or(0, |s| s.flat_len());
        let patch = spec.patch.as_ref().map_or(0, |s| s.flat_len());
        let len = Lengths {
            agents: n,
            obs: n * spec.observation.flat_len(),
            state: state.max(1),
            patch: n * patch.max(1),
        };
        Outputs {
            worlds: e,
            len,
            has_state: state > 0,
            has_patch: patch > 0,
            obs: vec![0.0; e * len.obs],
            rewards: vec![0.0; e * n],
            terminated: vec![false; e * n],
            truncated: vec![false; e * n],
            state: vec![0.0; e * len.state],
            patch: vec![0; e * len.patch],
            final_obs: vec![0.0; e * len.obs],
            final_mask: vec![false; e],
            shield: vec![0; e * n],
        }
    }

    pub fn lengths(&self) -> Lengths {
        self.len
    }
    /// Observations `[E, N, obs_dim]` (the sensor values, then the task's extras).
    pub fn obs(&self) -> &[f32] {
        &self.obs
    }
    pub fn rewards(&self) -> &[f32] {
        &self.rewards
    }
    pub fn terminated(&self) -> &[bool] {
        &self.terminated
    }
    pub fn truncated(&self) -> &[bool] {
        &self.truncated
    }
    /// Global state `[E, S]` (empty if disabled).
    pub fn state(&self) -> &[f32] {
        if self.has_state { &self.state } else { &[] }
    }
    /// Screen patches `[E, N, P, P, 3]` (empty if disabled).
    pub fn patch(&self) -> &[u8] {
        if self.has_patch { &self.patch } else { &[] }
    }
    /// Final observations of worlds that ended in the last step (same-step autoreset) `[E, N, obs_dim]`.
    pub fn final_obs(&self) -> &[f32] {
        &self.final_obs
    }
    /// Which worlds ended (and were reset) in the last step, same-step autoreset `[E]`.
    pub fn final_mask(&self) -> &[bool] {
        &self.final_mask
    }
    /// What the safety shield did to each agent's last command `[E, N]`: bit 0 (1) the speed was
    /// capped, bit 1 (2) it would have crossed a virtual wall. All zero without a shield.
    pub fn shield_flags(&self) -> &[u8] {
        &self.shield
    }

    /// Raw pointers to the buffers, for bindings that hand out views. They stay valid and fixed for
    /// the life of `self` (the buffers are never reallocated).
    pub fn ptrs(&mut self) -> BufferPtrs {
        BufferPtrs {
            obs: self.obs.as_mut_ptr(),
            rewards: self.rewards.as_mut_ptr(),
            terminated: self.terminated.as_mut_ptr(),
            truncated: self.truncated.as_mut_ptr(),
            state: self.state.as_mut_ptr(),
            patch: self.patch.as_mut_ptr(),
            final_obs: self.final_obs.as_mut_ptr(),
            final_mask: self.final_mask.as_mut_ptr(),
            shield: self.shield.as_mut_ptr(),
        }
    }

    /// Clears rewards, flags and final masks (after a reset).
    pub fn clear(&mut self) {
        self.rewards.fill(0.0);
        self.terminated.fill(false);
        self.truncated.fill(false);
        self.final_mask.fill(false);
        self.shield.fill(0);
    }

    /// Every world's slices.
    pub fn all(&mut self) -> OutSlices<'_> {
        OutSlices {
            len: self.len,
            obs: &mut self.obs,
            rewards: &mut self.rewards,
            terminated: &mut self.terminated,
            truncated: &mut self.truncated,
            state: &mut self.state,
            patch: &mut self.patch,
            final_obs: &mut self.final_obs,
            final_mask: &mut self.final_mask,
            shield: &mut self.shield,
        }
    }

    /// World `w`'s slices.
    pub fn world(&mut self, w: usize) -> OutSlices<'_> {
        debug_assert!(w < self.worlds);
        self.all().into_world(w)
    }
}

/// The slices of consecutive worlds' outputs (one world's, a chunk's or all).
pub struct OutSlices<'a> {
    len: Lengths,
    pub obs: &'a mut [f32],
    pub rewards: &'a mut [f32],
    pub terminated: &'a mut [bool],
    pub truncated: &'a mut [bool],
    pub state: &'a mut [f32],
    pub patch: &'a mut [u8],
    pub final_obs: &'a mut [f32],
    pub final_mask: &'a mut [bool],
    pub shield: &'a mut [u8],
}

impl<'a> OutSlices<'a> {
    /// The slices of the `i`-th world of these.
    pub fn world(&mut self, i: usize) -> OutSlices<'_> {
        self.reborrow().into_world(i)
    }

    /// The same slices, borrowed again (for a step that walks the batch twice).
    pub fn reborrow(&mut self) -> OutSlices<'_> {
        OutSlices {
            len: self.len,
            obs: self.obs,
            rewards: self.rewards,
            terminated: self.terminated,
            truncated: self.truncated,
            state: self.state,
            patch: self.patch,
            final_obs: self.final_obs,
            final_mask: self.final_mask,
            shield: self.shield,
        }
    }

    pub fn into_world(self, i: usize) -> OutSlices<'a> {
        let len = self.len;
        let part = |n: usize| i * n..(i + 1) * n;
        OutSlices {
            len,
            obs: &mut self.obs[part(len.obs)],
            rewards: &mut self.rewards[part(len.agents)],
            terminated: &mut self.terminated[part(len.agents)],
            truncated: &mut self.truncated[part(len.agents)],
            state: &mut self.state[part(len.state)],
            patch: &mut self.patch[part(len.patch)],
            final_obs: &mut self.final_obs[part(len.obs)],
            final_mask: &mut self.final_mask[i..i + 1],
            shield: &mut self.shield[part(len.agents)],
        }
    }

    /// The rewards and flags a step ends with ([`Episode::finish_step`]).
    pub fn agent_out(&mut self) -> AgentOut<'_> {
        AgentOut {
            rewards: self.rewards,
            terminated: self.terminated,
            truncated: self.truncated,
        }
    }

    /// These slices cut into parts of `c` worlds, for a parallel iteration over chunks of worlds.
    pub fn par_chunks(self, c: usize) -> impl IndexedParallelIterator<Item = OutSlices<'a>> {
        let len = self.len;
        (self.obs.par_chunks_mut(c * len.obs))
            .zip(self.rewards.par_chunks_mut(c * len.agents))
            .zip(self.terminated.par_chunks_mut(c * len.agents))
            .zip(self.truncated.par_chunks_mut(c * len.agents))
            .zip(self.state.par_chunks_mut(c * len.state))
            .zip(self.patch.par_chunks_mut(c * len.patch))
            .zip(self.final_obs.par_chunks_mut(c * len.obs))
            .zip(self.final_mask.par_chunks_mut(c))
            .zip(self.shield.par_chunks_mut(c * len.agents))
            .map(
                move |((((((((obs, rw), te), tr), state), patch), fo), fm), shield)| OutSlices {
                    len,
                    obs,
                    rewards: rw,
                    terminated: te,
                    truncated: tr,
                    state,
                    patch,
                    final_obs: fo,
                    final_mask: fm,
                    shield,
                },
            )
    }
}

/// What an arena's observation, state and patch outputs are made of: one writer for the batch's
/// worlds and the plants' arena.
#[derive(Clone, Copy, Debug)]
pub struct Writer {
    /// The robots' top wheel speed (observations are fractions of it).
    pub max_speed: f32,
    /// Episode length in steps (the state's elapsed fraction).
    pub max_cycles: u64,
    /// Whether the global state is written.
    pub state: bool,
    pub patch: Option<PatchConfig>,
}

impl Writer {
    /// Writes one world's observations (with the task's extras), global state and patches of
    /// `arena` in `episode` into `out`.
    pub fn write(
        &self,
        task: &dyn Task,
        arena: &dyn ArenaView,
        episode: &Episode,
        out: &mut OutSlices,
    ) {
        write_task_obs(arena, task, episode.task_state(), self.max_speed, out.obs);
        if self.state {
            write_state(arena, episode.steps, self.max_cycles, out.state);
        }
        if let Some(p) = &self.patch {
            write_patch(arena, task.agents(), p, out.patch);
        }
    }
}

/// Raw pointers to an [`Outputs`]' buffers (see [`Outputs::ptrs`]).
pub struct BufferPtrs {
    pub obs: *mut f32,
    pub rewards: *mut f32,
    pub terminated: *mut bool,
    pub truncated: *mut bool,
    pub state: *mut f32,
    pub patch: *mut u8,
    pub final_obs: *mut f32,
    pub final_mask: *mut bool,
    pub shield: *mut u8,
}
