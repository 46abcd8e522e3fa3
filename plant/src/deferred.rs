//! A plant's step in two halves, for a task written in Python (`colcos.Task`): the arena moves and
//! waits; the task's hooks run on its state (tracked poses on the twin and the rig); `conclude`
//! hands out their rewards and terminations through the same episode bookkeeping as a plain step.
use crate::{LiveEnv, PlantError};
use colcos_env::{Actions, EnvError};

impl LiveEnv {
    /// The first half of a step: the actions sent, one tick; the rewards wait for [`Self::conclude`].
    pub fn step_deferred(&mut self, actions: Actions) -> Result<(), PlantError> {
        let end = self.advance(actions)?;
        self.awaiting = Some(end);
        Ok(())
    }

    /// The second half: `rewards` and `terminated`, one per agent.
    pub fn conclude(&mut self, rewards: &[f32], terminated: &[bool]) -> Result<(), PlantError> {
        let Some(end) = self.awaiting else {
            return Err(PlantError::State(
                "nothing to conclude: call step_deferred() first".into(),
            ));
        };
        let n = self.spec.num_agents;
        if rewards.len() != n || terminated.len() != n {
            return Err(EnvError::Action(format!(
                "expected {n} rewards and terminations (num_envs 1 x agents {n}), got {} and {}",
                rewards.len(),
                terminated.len()
            ))
            .into());
        }
        if let Some(k) = rewards.iter().position(|r| !r.is_finite()) {
            return Err(EnvError::Action(format!(
                "reward of world 0, agent robot_{k} is {} (must be finite)",
                rewards[k]
            ))
            .into());
        }
        self.awaiting = None;
        self.finish(end, Some((rewards, terminated)));
        Ok(())
    }

    /// How this plant reads actions (the simulated batch's decoder).
    pub fn action_decoder(&self) -> &colcos_env::ActionDecoder {
        &self.decoder
    }

    /// Whether a deferred step waits for [`Self::conclude`].
    pub fn is_awaiting(&self) -> bool {
        self.awaiting.is_some()
    }
}
