//! Robots placed by a task written in Python as a world starts an episode (`ctx.place` of
//! `colcos.Task.reset`): the world's robots move, and its outputs are written afresh.
use super::VecEnv;
use crate::error::{EnvError, Result};
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
        let slot = &self.slots[w];
        let out = &mut self.out.world(w);
        (self.writer).write(self.task.as_ref(), &slot.world, &slot.episode, out);
        Ok(())
    }
}
