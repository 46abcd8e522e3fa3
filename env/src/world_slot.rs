//! One world of a batch: the sim world, the behaviours of its scripted robots, and episode bookkeeping.
use crate::backend::EnvBackend;
use crate::error::Result;
use crate::task::Task;
use colcos_sim::behaviour::{Behaviour, WheelCommand, registry};
use colcos_sim::rng::{self, SimRng, Stream};
use colcos_sim::robot::RapierHost;
use colcos_sim::scenario::Scenario;
use colcos_sim::world::World;

/// The world index passed to [`World::with_index`] for episode `episode` of batch world `w`: every
/// (world, episode) pair has its own random streams, whatever the order worlds are reset in.
pub fn world_index(w: usize, episode: u64) -> u64 {
    (w as u64) | (episode << 32)
}

pub(crate) struct WorldSlot {
    pub world: World,
    /// Scripted (non-agent) robots: index, behaviour, random stream.
    scripted: Vec<(usize, Box<dyn Behaviour>, SimRng)>,
    /// Wheel commands of every robot for the next step.
    pub commands: Vec<WheelCommand>,
    /// Episodes started in this world since the seed was set.
    pub episode: u64,
    /// Steps taken in this episode.
    pub steps: u64,
    /// Agents that have terminated in this episode.
    pub terminated: Vec<bool>,
    /// Scratch: `terminated` before the last evaluation.
    pub prev_terminated: Vec<bool>,
    /// Every agent is terminated or truncated.
    pub done: bool,
}

impl WorldSlot {
    /// Builds episode `episode` of batch world `w`, its rapier steps in `host` (the host and the
    /// world's slot there) if given.
    pub fn build(
        scenario: &Scenario,
        task: &dyn Task,
        backend: &EnvBackend,
        w: usize,
        episode: u64,
        host: Option<(&mut RapierHost, usize)>,
    ) -> Result<Self> {
        let index = world_index(w, episode);
        let mut world = World::with_index(scenario, index)?;
        backend.install(&mut world)?;
        let agents = task.agents();
        let mut scripted = Vec::new();
        let mut first = 0;
        for (g, group) in scenario.spec.robots.iter().enumerate() {
            for i in first..first + group.count {
                if !agents.contains(&i) {
                    let key = format!("robots[{g}]");
                    let behaviour = registry::build_for_group(group, &scenario.spec.robot, &key)?;
                    let rng = rng::stream_of(scenario.spec.seed, index, Stream::Scripted(i));
                    scripted.push((i, behaviour, rng));
                }
            }
            first += group.count;
        }
        let robots = world.robot_count();
        if task.on_reset(world.pheromones_mut()) {
            // One still step so that the sensors see what the task changed.
            world.step_with_commands(&vec![WheelCommand::STOP; robots]);
        }
        if let Some((host, slot)) = host {
            world.attach_physics(host, slot);
        }
        Ok(WorldSlot {
            world,
            scripted,
            commands: vec![WheelCommand::STOP; robots],
            episode,
            steps: 0,
            terminated: vec![false; agents.len()],
            prev_terminated: vec![false; agents.len()],
            done: false,
        })
    }

    /// Lets the scripted robots decide their commands from their current observations.
    pub fn decide_scripted(&mut self) {
        let obs = self.world.observations();
        for (i, behaviour, rng) in &mut self.scripted {
            self.commands[*i] = behaviour.act(&obs[*i], rng);
        }
    }
}
