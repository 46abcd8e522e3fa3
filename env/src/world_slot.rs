//! One world of a batch: the sim world (whose robots that are not agents decide with their own
//! behaviours), the agents' commands, and episode bookkeeping.
use crate::backend::EnvBackend;
use crate::episode::Episode;
use crate::error::Result;
use crate::task::Task;
use colcos_sim::behaviour::WheelCommand;
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
    /// Each robot's controller for the next step: the agents' commands (`Some`), the others' own
    /// behaviours (`None`).
    pub overrides: Vec<Option<WheelCommand>>,
    pub episode: Episode,
    /// Stepped, its rewards and terminations not yet handed out (a task written in Python).
    pub awaiting: bool,
    /// Built since the GPU batch last loaded its grids (the CPU's are the world's; see `gpu_stage`;
    /// read only with the `gpu` feature).
    #[cfg_attr(not(feature = "gpu"), allow(dead_code))]
    pub fresh: bool,
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
        if !task.reads_other_robots_colour() {
            world.skip_unread_colour(agents);
        }
        let robots = world.robot_count();
        let mut overrides = vec![None; robots];
        for &i in agents {
            overrides[i] = Some(WheelCommand::STOP);
        }
        if task.on_reset(world.pheromones_mut()) {
            // One still step so that the sensors see what the task changed.
            world.step_with_commands(&vec![WheelCommand::STOP; robots]);
        }
        backend.hand_over(&mut world);
        if let Some((host, slot)) = host {
            world.attach_physics(host, slot);
        }
        Ok(WorldSlot {
            world,
            overrides,
            episode: Episode::new(episode, agents.len()),
            awaiting: false,
            fresh: true,
        })
    }
}
