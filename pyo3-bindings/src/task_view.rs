//! The state of every world (or of a plant's one arena) as flat arrays for a task written in Python:
//! gathered with the GIL released, handed to numpy in `task_hooks`.
use colcos_env::encoding::OBS_DIM;
use colcos_env::world_output::write_obs;
use colcos_sim::tracker::TrackedPose;
use colcos_sim::world::ArenaView;

/// One step's state of every world, each array flat in world order.
pub(crate) struct View {
    pub dims: Dims,
    pub robots: RobotRows,
    /// Each agent's deposit actions `[E, N, D]` and observations `[E, N, OBS_DIM]`.
    pub deposits: Vec<f32>,
    pub obs: Vec<f32>,
    /// Each world's episode counters `[E]`.
    pub worlds: Vec<Counters>,
}

/// The sizes of a [`View`]: `e` worlds of `r` robots, `n` agents with `d` deposit actions each.
#[derive(Clone, Copy)]
pub(crate) struct Dims {
    pub e: usize,
    pub r: usize,
    pub n: usize,
    pub d: usize,
}

/// Each robot's state `[E, R, ...]`: its true and tracked poses (x, y, heading), whether the tracker
/// saw it, its wheel speeds and its last commands (left, right).
pub(crate) struct RobotRows {
    pub poses: Vec<f32>,
    pub tracked: Vec<f32>,
    pub seen: Vec<bool>,
    pub wheels: Vec<f32>,
    pub commands: Vec<f32>,
}

/// One world's episode counters for [`View::push`].
pub(crate) struct Counters {
    /// Steps of the episode, the deferred step's included.
    pub steps: u64,
    /// Moved in the deferred step (false: only reset).
    pub stepped: bool,
    pub episode: u64,
    pub time: f32,
}

impl View {
    pub fn new(dims: Dims) -> View {
        let Dims { e, r, n, d } = dims;
        View {
            dims,
            robots: RobotRows {
                poses: Vec::with_capacity(e * r * 3),
                tracked: Vec::with_capacity(e * r * 3),
                seen: Vec::with_capacity(e * r),
                wheels: Vec::with_capacity(e * r * 2),
                commands: Vec::with_capacity(e * r * 2),
            },
            deposits: Vec::with_capacity(e * n * d),
            obs: Vec::with_capacity(e * n * OBS_DIM),
            worlds: Vec::with_capacity(e),
        }
    }

    /// Appends one world: `arena` (a simulated world, or a plant's host with its tracked poses as
    /// its poses), the tracker's view, each agent's deposit actions.
    pub fn push<'a>(
        &mut self,
        arena: &dyn ArenaView,
        tracked: &[TrackedPose],
        agents: &[usize],
        deposits: impl Fn(usize) -> &'a [f32],
        max_speed: f32,
        c: Counters,
    ) {
        // The observations of now (a deferred step's outputs are written when it is concluded).
        let start = self.obs.len();
        self.obs.resize(start + agents.len() * OBS_DIM, 0.0);
        write_obs(arena, agents, max_speed, &mut self.obs[start..]);
        let rows = &mut self.robots;
        for p in arena.poses() {
            rows.poses.extend([p.pos.x, p.pos.y, p.heading]);
        }
        for t in tracked {
            rows.tracked
                .extend([t.pose.pos.x, t.pose.pos.y, t.pose.heading]);
            rows.seen.push(t.seen);
        }
        for slot in arena.robots() {
            rows.wheels.extend([slot.drive.left, slot.drive.right]);
            rows.commands
                .extend([slot.command.left, slot.command.right]);
        }
        for &i in agents {
            self.deposits.extend_from_slice(deposits(i));
        }
        self.worlds.push(c);
    }
}
