//! Robots placed by a task written in Python as a world starts an episode (`ctx.place` of
//! `colcos.Task.reset`): the world's robots move, and its outputs are written afresh.
use super::VecEnv;
use crate::error::{EnvError, Result};
use crate::world_output::{write_patch, write_state, write_task_obs};
use colcos_sim::robot::Pose;

impl VecEnv {
    /// Moves robots of world `w` to `placed` (robot index, pose), as if they had started there, and
    /// rewrites the world's observations, state and patches (its rewards and flags stay). Only a
    /// world that has not stepped in its episode may be placed; a pose that is not finite, leaves
    /// the arena or overlaps an obstacle or another robot is refused, naming the world and robot.
    pub fn place(&mut self, w: usize, placed: &[(usize, Pose)]) -> Result<()> {
        let e = self.spec.num_envs;
        let Some(slot) = self.slots.get_mut(w) else {
            return Err(EnvError::State(format!(
                "world {w} is not below num_envs = {e}"
            )));
        };
        if slot.awaiting || slot.episode.steps > 0 {
            return Err(EnvError::State(format!(
                "world {w} has stepped in this episode: robots are placed as it starts"
            )));
        }
        (slot.world)
            .place_robots(placed)
            .map_err(|m| EnvError::State(format!("world {w}: {m}")))?;
        let (n, d, sd, pl) = (
            self.spec.num_agents,
            self.obs_dim(),
            self.state_dim,
            self.patch_len,
        );
        let slot = &self.slots[w];
        let max_speed = self.scenario.spec.robot.max_wheel_speed;
        let task = self.task.as_ref();
        let obs = &mut self.obs[w * n * d..(w + 1) * n * d];
        write_task_obs(&slot.world, task, slot.episode.task_state(), max_speed, obs);
        if sd > 0 {
            let state = &mut self.state[w * sd..(w + 1) * sd];
            write_state(&slot.world, slot.episode.steps, self.spec.max_cycles, state);
        }
        if let Some(p) = &self.patch_cfg {
            let patch = &mut self.patch[w * n * pl..(w + 1) * n * pl];
            write_patch(&slot.world, task.agents(), p, patch);
        }
        Ok(())
    }
}
