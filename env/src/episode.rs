//! One episode's bookkeeping, shared by every environment of a task (each world of the batch, the
//! plants' arena): how many steps it has taken, which agents have terminated, and how a step ends.
//! "What happens when an agent terminates" is written here once.
use crate::task::{Outcome, Task, TaskState};
use colcos_sim::world::ArenaView;

/// The per-agent outputs a step ends with.
pub struct AgentOut<'a> {
    pub rewards: &'a mut [f32],
    pub terminated: &'a mut [bool],
    pub truncated: &'a mut [bool],
}

/// How a step ended, besides the task's verdict.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StepEnd {
    /// The arena stepped.
    Stepped,
    /// The arena stepped and can step no more (a replayed log's last tick): every agent still
    /// running is truncated.
    LastStep,
    /// Nothing happened (a replayed log had no tick left): no reward, every agent truncated.
    Nothing,
}

/// One episode of one arena.
#[derive(Clone, Debug)]
pub struct Episode {
    /// Episodes started in this arena since the seed was set (0 for the first).
    pub index: u64,
    /// Steps taken in this episode.
    pub steps: u64,
    /// Agents that have terminated in this episode.
    pub terminated: Vec<bool>,
    /// `terminated` before the last step: agents whose rewards and shield flags no longer count.
    pub was_terminated: Vec<bool>,
    /// Every agent is terminated or truncated.
    pub done: bool,
    /// The task's memory of this episode ([`Task::initial_state`]), made at its first step.
    pub state: Option<TaskState>,
}

impl Episode {
    /// Episode `index` of an arena with `agents` agents, before its first step.
    pub fn new(index: u64, agents: usize) -> Self {
        Episode {
            index,
            steps: 0,
            terminated: vec![false; agents],
            was_terminated: vec![false; agents],
            done: false,
            state: None,
        }
    }

    /// Starts episode `index` in place.
    pub fn restart(&mut self, index: u64) {
        self.index = index;
        self.steps = 0;
        self.terminated.fill(false);
        self.was_terminated.fill(false);
        self.done = false;
        self.state = None;
    }

    /// The task's memory of this episode so far (empty before its first step).
    pub fn task_state(&self) -> &[u32] {
        self.state.as_deref().unwrap_or(&[])
    }

    /// The end of a step of `world`: the task's rewards and terminations, no reward for an agent
    /// that had already terminated, truncation at `max_cycles` steps (or as `end` says). Writes
    /// `out` and returns whether the episode is over (also `self.done`).
    pub fn finish_step(
        &mut self,
        task: &dyn Task,
        world: &dyn ArenaView,
        max_cycles: u64,
        end: StepEnd,
        out: AgentOut,
    ) -> bool {
        let mut state = self.state.take().unwrap_or_else(|| task.initial_state());
        let evaluate = |rewards: &mut [f32], terminated: &mut [bool]| {
            let out = Outcome {
                rewards,
                terminated,
            };
            task.evaluate(world, &mut state, out)
        };
        let done = self.finish_with(evaluate, max_cycles, end, out);
        self.state = Some(state);
        done
    }

    /// [`Self::finish_step`] with rewards and terminations given (a task written in Python, whose
    /// hooks ran on the whole batch): `terminated` only ever sets an agent's flag, never clears it.
    pub fn finish_given(
        &mut self,
        rewards: &[f32],
        terminated: &[bool],
        max_cycles: u64,
        end: StepEnd,
        out: AgentOut,
    ) -> bool {
        let evaluate = |r: &mut [f32], t: &mut [bool]| {
            r.copy_from_slice(rewards);
            for (mine, &given) in t.iter_mut().zip(terminated) {
                *mine |= given;
            }
        };
        self.finish_with(evaluate, max_cycles, end, out)
    }

    fn finish_with(
        &mut self,
        evaluate: impl FnOnce(&mut [f32], &mut [bool]),
        max_cycles: u64,
        end: StepEnd,
        out: AgentOut,
    ) -> bool {
        self.steps += 1;
        self.was_terminated.copy_from_slice(&self.terminated);
        evaluate(out.rewards, &mut self.terminated);
        for (r, &was) in out.rewards.iter_mut().zip(&self.was_terminated) {
            if was || end == StepEnd::Nothing {
                *r = 0.0;
            }
        }
        let truncate = self.steps >= max_cycles || end != StepEnd::Stepped;
        let mut done = true;
        for ((&term, t), tr) in self
            .terminated
            .iter()
            .zip(out.terminated.iter_mut())
            .zip(out.truncated.iter_mut())
        {
            *t = term;
            *tr = truncate && !term;
            done &= term || truncate;
        }
        self.done = done;
        done
    }
}
