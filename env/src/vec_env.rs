//! The batched core: `E` worlds of `N` agents stepped with rayon into flat buffers allocated once.
//!
//! Ownership model: the environment owns every output buffer (`[E, N, obs_dim]` observations,
//! `[E, N]` rewards and flags, ...); they are allocated at construction and never reallocated, so a
//! binding may hand out views of them that stay valid for the environment's lifetime. Each `step` and
//! `reset` overwrites them in place.
use crate::actions::{ActionDecoder, Actions};
use crate::backend::EnvBackend;
use crate::batch_step::{Chunks, conclude_batch, step_batch};
use crate::config::{ActionKind, AutoresetMode, EnvConfig};
use crate::error::{EnvError, Result};
use crate::outputs::{Outputs, Writer};
use crate::spaces::{EnvSpec, Space};
use crate::task::{Task, registry};
use crate::world_output::obs_dim;
pub use crate::world_output::render_world;
#[cfg(feature = "gpu")]
use crate::world_output::render_world_with;
use crate::world_slot::WorldSlot;
pub use crate::world_step::shield_bits;
use crate::world_step::{Ctx, Evaluation, step_world};
use colcos_sim::scenario::Scenario;
use colcos_sim::shield::Shield;
use colcos_sim::world::World;
use rayon::prelude::*;

mod place;

/// The parts of a step whose seconds `VecEnv::gpu_stage_seconds` adds up: motion on the CPU, the GPU
/// stage's four (loading new worlds and queueing trails, recording the field passes, writing the
/// sensors' centres, sensing with the wait for the GPU and the read-back), observations and rewards.
pub const GPU_STAGE_PARTS: [&str; 6] = [
    "motion",
    "loads and trails",
    "field passes",
    "sensor centres",
    "sensing and wait",
    "observations and rewards",
];

pub struct VecEnv {
    spec: EnvSpec,
    task: Box<dyn Task>,
    /// The scenario with the current seed.
    scenario: Scenario,
    backend: EnvBackend,
    mode: AutoresetMode,
    pool: rayon::ThreadPool,
    slots: Vec<WorldSlot>,
    /// The chunks the worlds are stepped in, with their rapier hosts (see `batch_step`).
    chunks: Chunks,
    /// Every world's grid pheromones resident on the GPU (`backend = "gpu"` where they allow it).
    #[cfg(feature = "gpu")]
    gpu: Option<crate::gpu_stage::GpuStage>,
    out: Outputs,
    writer: Writer,
    shield: Option<Shield>,
    /// Scratch: decoded wheel commands of the agents `[E, N]`.
    decoder: ActionDecoder,
    commands: Vec<colcos_sim::behaviour::WheelCommand>,
    /// Each agent's deposit rate fractions of this step, `[E, N, D]`.
    deposit_rates: Vec<f32>,
    needs_reset: bool,
    /// A deferred step waits for [`VecEnv::conclude`].
    awaiting: bool,
}

impl VecEnv {
    pub fn new(cfg: &EnvConfig) -> Result<Self> {
        if cfg.num_envs == 0 {
            return Err(EnvError::param("num_envs", "must be at least 1"));
        }
        let (task, mut scenario) = registry::build(&cfg.task, &cfg.scenario, &cfg.params)?;
        scenario.spec.seed = cfg.seed;
        if let Some(b) = cfg.backend {
            scenario.spec.field.backend = b;
        }
        if let Some(p) = cfg.physics {
            scenario.spec.physics = p;
        }
        let mut backend =
            EnvBackend::resolve(scenario.spec.field.backend, cfg.num_envs, &scenario)?;
        let max_cycles = if cfg.max_cycles > 0 {
            cfg.max_cycles
        } else {
            scenario.steps().max(1)
        };
        let n = task.agents().len();
        let robots = scenario.robot_count();
        let e = cfg.num_envs;
        if let Some(p) = cfg.patch {
            if p.pixels == 0 || p.pixels > 256 {
                return Err(EnvError::param(
                    "patch_pixels",
                    format!("{} must be in 1..=256", p.pixels),
                ));
            }
            if !(p.side.is_finite() && p.side > 0.0) {
                return Err(EnvError::param(
                    "patch_side",
                    format!("{} must be a positive length in m", p.side),
                ));
            }
        }
        let state_dim = if cfg.global_state { 4 * robots + 1 } else { 0 };
        let decoder = ActionDecoder::new(
            cfg.action == ActionKind::Discrete,
            n,
            crate::actions::deposit_actions_per_agent(&scenario, task.agents())?,
            scenario.spec.robot.max_wheel_speed,
        );
        let threads = cfg.num_threads.unwrap_or(0);
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .thread_name(|i| format!("colcos-env-{i}"))
            .build()
            .map_err(|err| EnvError::param("num_threads", err.to_string()))?;
        let obs_dim = obs_dim(task.as_ref());
        let spec = EnvSpec {
            task: cfg.task.clone(),
            env_name: format!("colcos_{}_v0", cfg.task),
            num_envs: e,
            num_agents: n,
            num_robots: robots,
            agent_names: (0..n).map(|i| format!("robot_{i}")).collect(),
            agent_robots: task.agents().to_vec(),
            observation: Space::Box {
                low: -1.0,
                high: 1.0,
                shape: vec![obs_dim],
                dtype: "float32",
            },
            extra_obs: task.extra_observations().to_vec(),
            action: match cfg.action {
                ActionKind::Continuous => Space::Box {
                    low: -1.0,
                    high: 1.0,
                    shape: vec![decoder.width()],
                    dtype: "float32",
                },
                ActionKind::Discrete => Space::Discrete {
                    n: decoder.discrete_count(),
                },
            },
            state: cfg.global_state.then(|| Space::Box {
                low: -1.0,
                high: 1.0,
                shape: vec![state_dim],
                dtype: "float32",
            }),
            patch: cfg.patch.map(|p| Space::Box {
                low: 0.0,
                high: 255.0,
                shape: vec![p.pixels, p.pixels, 3],
                dtype: "uint8",
            }),
            max_cycles,
            dt: scenario.spec.dt,
        };
        let shield = cfg.shield.then(|| {
            Shield::new(
                scenario.spec.rig.shield,
                scenario.arena_size(),
                scenario.spec.robot.max_wheel_speed,
            )
        });
        let slots = pool.install(|| {
            (0..e)
                .into_par_iter()
                .map(|w| WorldSlot::build(&scenario, task.as_ref(), &backend, w, 0, None))
                .collect::<Result<Vec<_>>>()
        })?;
        let mut slots = slots;
        let mut chunks = Chunks::new(&scenario, &slots);
        pool.install(|| chunks.attach_all(&mut slots));
        backend.settle(&slots[0].world);
        let writer = Writer {
            max_speed: scenario.spec.robot.max_wheel_speed,
            max_cycles,
            state: cfg.global_state,
            patch: cfg.patch,
        };
        #[cfg(feature = "gpu")]
        let gpu = crate::gpu_stage::GpuStage::for_backend(&backend, &mut slots)?;
        let mut env = VecEnv {
            out: Outputs::new(&spec),
            writer,
            spec,
            task,
            scenario,
            backend,
            mode: cfg.autoreset,
            pool,
            slots,
            chunks,
            #[cfg(feature = "gpu")]
            gpu,
            shield,
            commands: vec![Default::default(); e * n],
            deposit_rates: vec![0.0; e * n * decoder.deposits()],
            decoder,
            needs_reset: true,
            awaiting: false,
        };
        env.write_all_outputs();
        Ok(env)
    }

    pub fn spec(&self) -> &EnvSpec {
        &self.spec
    }
    /// Entries of an agent's observation: the 17 sensor values and the task's extras.
    pub fn obs_dim(&self) -> usize {
        self.spec.observation.flat_len()
    }
    /// The task's memory of world `e`'s episode (empty before its first step; see [`Task`]).
    pub fn task_state(&self, e: usize) -> &[u32] {
        self.slots[e].episode.task_state()
    }
    /// How this environment reads actions (the plants decode theirs with the same).
    pub fn action_decoder(&self) -> &ActionDecoder {
        &self.decoder
    }
    pub fn task(&self) -> &dyn Task {
        self.task.as_ref()
    }
    pub fn scenario(&self) -> &Scenario {
        &self.scenario
    }
    /// The field backend of the worlds (see [`EnvBackend`]).
    pub fn backend(&self) -> &EnvBackend {
        &self.backend
    }
    pub fn autoreset_mode(&self) -> AutoresetMode {
        self.mode
    }
    /// Current base seed.
    pub fn seed(&self) -> u64 {
        self.scenario.spec.seed
    }
    /// The sim world of batch world `e`.
    pub fn world(&self, e: usize) -> Option<&World> {
        self.slots.get(e).map(|s| &s.world)
    }
    /// Steps taken in the current episode of each world.
    pub fn episode_steps(&self, e: usize) -> u64 {
        self.slots[e].episode.steps
    }
    /// Number of the current episode of world `e` since the seed was last set.
    pub fn episode(&self, e: usize) -> u64 {
        self.slots[e].episode.index
    }
    /// Whether world `e` has finished its episode (and awaits a reset).
    /// World `e` moved in the last deferred step and awaits [`Self::conclude`].
    pub fn is_awaiting(&self, e: usize) -> bool {
        self.slots[e].awaiting
    }
    pub fn is_done(&self, e: usize) -> bool {
        self.slots[e].episode.done
    }

    /// The output buffers (observations, rewards, flags, state, patches, final observations, the
    /// shield's flags), overwritten by every step and reset.
    pub fn outputs(&self) -> &Outputs {
        &self.out
    }
    /// Raw pointers to the output buffers, for bindings that hand out views (see [`Outputs::ptrs`]).
    pub fn buffer_ptrs(&mut self) -> crate::outputs::BufferPtrs {
        self.out.ptrs()
    }

    /// Resets the worlds selected by `mask` (all if `None`). A `seed` becomes the new base seed and
    /// restarts the episode count of the reset worlds, so `reset(seed)` reproduces a run exactly.
    pub fn reset(&mut self, seed: Option<u64>, mask: Option<&[bool]>) -> Result<()> {
        let e = self.spec.num_envs;
        // A deferred step not yet concluded is dropped: its worlds start over or step on.
        self.awaiting = false;
        self.slots.iter_mut().for_each(|s| s.awaiting = false);
        if let Some(m) = mask.filter(|m| m.len() != e) {
            return Err(EnvError::Action(format!(
                "reset mask has {} entries, expected num_envs = {e}",
                m.len()
            )));
        }
        if let Some(s) = seed {
            self.scenario.spec.seed = s;
        }
        let (scenario, task, backend) = (&self.scenario, self.task.as_ref(), &self.backend);
        // A seed restarts the episode count; the first reset after construction replays episode 0.
        let restart = seed.is_some();
        let first = self.needs_reset;
        let (slots, chunks) = (&mut self.slots, &mut self.chunks);
        let size = chunks.size();
        self.pool.install(|| {
            chunks.par_iter_mut(slots).enumerate().try_for_each(
                |(k, (slots, mut host))| -> Result<()> {
                    for (i, slot) in slots.iter_mut().enumerate() {
                        let w = k * size + i;
                        if mask.is_none_or(|m| m[w]) {
                            let episode = if restart {
                                0
                            } else if first {
                                slot.episode.index
                            } else {
                                slot.episode.index + 1
                            };
                            let host = host.as_deref_mut().map(|h| (h, i));
                            *slot = WorldSlot::build(scenario, task, backend, w, episode, host)?;
                        }
                    }
                    Ok(())
                },
            )
        })?;
        if mask.is_none() {
            self.needs_reset = false;
        }
        self.write_all_outputs();
        Ok(())
    }

    /// One step of every world. Agents that have terminated are stopped and their actions ignored.
    pub fn step(&mut self, actions: Actions) -> Result<()> {
        self.run(Some(actions), Evaluation::Task)
    }

    /// The first half of a step for a task written in Python: every world moves, and waits for
    /// [`Self::conclude`] to hand out its rewards and terminations (the task's hooks run on the
    /// whole batch in between; the Rust task's own evaluation is not used).
    pub fn step_deferred(&mut self, actions: Actions) -> Result<()> {
        self.run(Some(actions), Evaluation::Deferred)?;
        self.awaiting = true;
        Ok(())
    }

    /// The second half of [`Self::step_deferred`]: `rewards` and `terminated`, `[E, N]`, for the
    /// worlds that stepped (a world that only reset this step keeps its zeros); episodes end, the
    /// outputs are written and, in same-step mode, finished worlds reset.
    pub fn conclude(&mut self, rewards: &[f32], terminated: &[bool]) -> Result<()> {
        if !self.awaiting {
            return Err(EnvError::State(
                "nothing to conclude: call step_deferred() first".into(),
            ));
        }
        let (e, n) = (self.spec.num_envs, self.spec.num_agents);
        if rewards.len() != e * n || terminated.len() != e * n {
            return Err(EnvError::Action(format!(
                "expected {} rewards and terminations (num_envs {e} x agents {n}), got {} and {}",
                e * n,
                rewards.len(),
                terminated.len()
            )));
        }
        if let Some(k) = rewards.iter().position(|r| !r.is_finite()) {
            return Err(EnvError::Action(format!(
                "reward of world {}, agent robot_{} is {} (must be finite)",
                k / n,
                k % n,
                rewards[k]
            )));
        }
        self.awaiting = false;
        self.run(
            None,
            Evaluation::Given {
                rewards,
                terminated,
            },
        )
    }

    /// A step (with `actions`) or the conclusion of a deferred one (without).
    fn run(&mut self, actions: Option<Actions>, evaluation: Evaluation) -> Result<()> {
        if self.needs_reset {
            return Err(EnvError::State("call reset() before step()".into()));
        }
        if actions.is_some() && self.awaiting {
            return Err(EnvError::State(
                "the last step awaits its rewards: call conclude() first".into(),
            ));
        }
        if let Some(actions) = actions {
            self.decode(actions)?;
            let blocked = match self.mode {
                AutoresetMode::Disabled => self.slots.iter().position(|s| s.episode.done),
                _ => None,
            };
            if let Some(w) = blocked {
                return Err(EnvError::State(format!(
                    "world {w} has finished its episode; reset it (autoreset mode is disabled)"
                )));
            }
        }
        let ctx = Ctx {
            task: self.task.as_ref(),
            scenario: &self.scenario,
            backend: &self.backend,
            mode: self.mode,
            writer: self.writer,
            shield: self.shield,
            deposits: self.decoder.deposits(),
            evaluation,
        };
        let buffers = self.out.all();
        let (slots, chunks) = (&mut self.slots, &mut self.chunks);
        #[cfg(feature = "gpu")]
        if let (Some(stage), Some(_)) = (self.gpu.as_mut(), actions) {
            let (cmds, rates) = (&self.commands, &self.deposit_rates);
            let step = crate::gpu_step::step_batch_gpu;
            return (self.pool).install(|| step(&ctx, slots, chunks, stage, cmds, rates, buffers));
        }
        if actions.is_none() {
            return self
                .pool
                .install(|| conclude_batch(&ctx, slots, chunks, buffers));
        }
        if let [slot] = slots.as_mut_slice() {
            // One world (a PettingZoo `parallel_env`): step it on the calling thread. Handing a single
            // world to the pool costs two thread wake-ups per step, a third of the step at this size.
            let actions = (&self.commands[..], &self.deposit_rates[..]);
            return step_world(&ctx, 0, slot, actions, &mut buffers.into_world(0));
        }
        let (commands, rates) = (&self.commands, &self.deposit_rates);
        self.pool
            .install(|| step_batch(&ctx, slots, chunks, commands, rates, buffers))
    }

    /// Checks and decodes the actions into wheel commands.
    fn decode(&mut self, actions: Actions) -> Result<()> {
        self.decoder.decode(
            actions,
            self.spec.num_envs,
            &mut self.commands,
            &mut self.deposit_rates,
        )
    }

    /// Rewrites observations, state and patches of every world and clears rewards and flags.
    fn write_all_outputs(&mut self) {
        for (w, slot) in self.slots.iter().enumerate() {
            let out = &mut self.out.world(w);
            (self.writer).write(self.task.as_ref(), &slot.world, &slot.episode, out);
        }
        self.out.clear();
    }

    /// Seconds in the parts of the steps with the GPU batch so far, in the order of
    /// [`GPU_STAGE_PARTS`] (motion, the GPU stage's four parts, observations and rewards).
    pub fn gpu_stage_seconds(&self) -> Option<[f64; 6]> {
        #[cfg(feature = "gpu")]
        return self.gpu.as_ref().map(|g| g.seconds);
        #[cfg(not(feature = "gpu"))]
        None
    }

    /// Copies the GPU batch's fields into the worlds' CPU ones (`world(e).pheromones()`).
    pub fn sync_fields(&mut self) -> Result<()> {
        #[cfg(feature = "gpu")]
        if let Some(stage) = &self.gpu {
            stage.sync(&mut self.slots)?;
        }
        Ok(())
    }

    /// The screen with the robots drawn on it, `width` pixels wide, of world `e`.
    pub fn render(&self, e: usize, width: u32) -> Result<image::RgbImage> {
        let slot = self.slots.get(e).ok_or_else(|| {
            EnvError::param(
                "world",
                format!("{e} is not below num_envs = {}", self.spec.num_envs),
            )
        })?;
        #[cfg(feature = "gpu")]
        if let Some(g) = &self.gpu {
            let world = (&slot.world, &g.pheromones_of(e, slot)?);
            return Ok(render_world_with(
                world.0,
                world.1,
                self.task.agents(),
                width,
            ));
        }
        Ok(render_world(&slot.world, self.task.agents(), width))
    }
}

impl crate::baseline::Arenas for VecEnv {
    fn made(&self) -> crate::baseline::Made<'_> {
        (&self.spec, &self.scenario, &self.out, &self.decoder)
    }
    fn arena(&self, w: usize) -> &dyn colcos_sim::world::ArenaView {
        &self.slots[w].world
    }
    fn episode(&self, w: usize) -> &crate::Episode {
        &self.slots[w].episode
    }
}
