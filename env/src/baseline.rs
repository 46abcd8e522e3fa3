//! The hand-written behaviours as baseline policies over a batch: one controller per (world, agent),
//! either a sim behaviour deciding the wheels from the raw sensor readings the agent's observation
//! vector is made of, or one of the tasks' own policies ([`crate::policy`]) deciding the whole action,
//! deposit rates included, from the agent's observation row. It drives any [`Arenas`]: the batch's
//! simulated worlds or a plant's arena (a twin, the rig), so a hand-written behaviour is evaluated
//! where a learned policy is.
use crate::actions::ActionDecoder;
use crate::encoding::command_to_action;
use crate::episode::Episode;
use crate::error::{EnvError, Result};
use crate::outputs::Outputs;
use crate::policy::{self, AgentPolicy};
use crate::spaces::EnvSpec;
use colcos_sim::behaviour::{Behaviour, registry};
use colcos_sim::rng::{self, SimRng, Stream};
use colcos_sim::robot::ColiasParams;
use colcos_sim::scenario::Scenario;
use colcos_sim::world::ArenaView;

/// What a policy reads of an environment of a task: its spec, each arena's raw readings and episode
/// counters, and the agents' observation rows. The batch ([`crate::VecEnv`]) and the plants'
/// arena implement it.
pub trait Arenas {
    /// What the arenas were made with, fixed for their lifetime.
    fn made(&self) -> Made<'_>;
    /// Arena `w` (`w < spec().num_envs`).
    fn arena(&self, w: usize) -> &dyn ArenaView;
    /// Arena `w`'s current episode (its number and steps taken).
    fn episode(&self, w: usize) -> &Episode;

    fn spec(&self) -> &EnvSpec {
        self.made().0
    }
    /// The scenario the arenas were made from (its `[robot]` builds the behaviours).
    fn scenario(&self) -> &Scenario {
        self.made().1
    }
    fn outputs(&self) -> &Outputs {
        self.made().2
    }
    /// Entries of an agent's continuous action (the wheels and the deposit actions).
    fn action_width(&self) -> usize {
        self.made().3.width()
    }
}

/// The spec, scenario, output buffers and action decoder of an [`Arenas`].
pub type Made<'a> = (&'a EnvSpec, &'a Scenario, &'a Outputs, &'a ActionDecoder);

/// One agent's controller.
enum Controller {
    /// A sim behaviour: wheels only, no deposit.
    Behaviour(Box<dyn Behaviour>),
    /// A task's policy: the whole action.
    Agent(Box<dyn AgentPolicy>),
}

pub struct BaselinePolicy {
    name: String,
    params: toml::Table,
    /// The body of the env's robots (the scenario's `[robot]`).
    robot: ColiasParams,
    seed: u64,
    /// Entries of an agent's action (2 wheels and the deposit rates).
    width: usize,
    /// Per (world, agent): controller, random stream; rebuilt when the world starts a new episode.
    slots: Vec<(Controller, SimRng)>,
    /// (episode, steps) each world was at when its behaviours were last used.
    seen: Vec<(u64, u64)>,
}

impl BaselinePolicy {
    /// Behaviour `name` from the sim registry with `params` (a JSON object), or the task policy
    /// `name` (no parameters), for every agent of `env`.
    pub fn new(
        env: &dyn Arenas,
        name: &str,
        params: &serde_json::Value,
        seed: u64,
    ) -> Result<Self> {
        let params: toml::Table = match params {
            serde_json::Value::Null => toml::Table::new(),
            v => toml::Table::try_from(v).map_err(|e| {
                EnvError::param(
                    "params",
                    format!("not a table of TOML-compatible values: {e}"),
                )
            })?,
        };
        let robot = env.scenario().spec.robot;
        if policy::build(name).is_some() {
            if let Some(key) = params.keys().next() {
                return Err(EnvError::param(
                    format!("params.{key}"),
                    format!("policy {name:?} takes no parameters"),
                ));
            }
        } else {
            // Build once to check the name and parameters.
            registry::build_with(name, &params, "baseline", &robot)?;
        }
        let mut policy = BaselinePolicy {
            name: name.into(),
            params,
            robot,
            seed,
            width: env.action_width(),
            slots: Vec::new(),
            seen: Vec::new(),
        };
        let (e, n) = (env.spec().num_envs, env.spec().num_agents);
        for w in 0..e {
            for i in 0..n {
                policy.slots.push(policy.make(w, i, env.episode(w).index)?);
            }
            let ep = env.episode(w);
            policy.seen.push((ep.index, ep.steps));
        }
        Ok(policy)
    }

    /// Entries of each agent's action this policy writes: the env's continuous action width.
    pub fn width(&self) -> usize {
        self.width
    }

    fn make(&self, w: usize, i: usize, episode: u64) -> Result<(Controller, SimRng)> {
        let c = match policy::build(&self.name) {
            Some(p) => Controller::Agent(p),
            None => Controller::Behaviour(registry::build_with(
                &self.name,
                &self.params,
                "baseline",
                &self.robot,
            )?),
        };
        let world = crate::world_slot::world_index(w, episode);
        Ok((c, rng::stream_of(self.seed, world, Stream::Baseline(i))))
    }

    /// Continuous actions `[E, N, width]` for the env's current observations (a behaviour lays
    /// nothing: its deposit rates are 0).
    pub fn act(&mut self, env: &dyn Arenas, out: &mut [f32]) -> Result<()> {
        let spec = env.spec();
        let (e, n, a) = (spec.num_envs, spec.num_agents, self.width);
        if self.seen.len() != e || out.len() != e * n * a {
            return Err(EnvError::Action(format!(
                "baseline policy built for {} worlds; output must hold {} values",
                self.seen.len(),
                e * n * a
            )));
        }
        let d = spec.observation.flat_len();
        let obs = env.outputs().obs();
        for w in 0..e {
            let ep = env.episode(w);
            let now = (ep.index, ep.steps);
            if now.0 != self.seen[w].0 || now.1 < self.seen[w].1 {
                for i in 0..n {
                    self.slots[w * n + i] = self.make(w, i, now.0)?;
                }
            }
            self.seen[w] = now;
            let world = env.arena(w);
            let max = world.robot_params().max_wheel_speed;
            for (i, &robot) in spec.agent_robots.iter().enumerate() {
                let k = w * n + i;
                let (c, rng) = &mut self.slots[k];
                let row = &mut out[k * a..(k + 1) * a];
                match c {
                    Controller::Behaviour(b) => {
                        let cmd = b.act(&world.observations()[robot], rng);
                        row[..2].copy_from_slice(&command_to_action(cmd, max));
                        row[2..].fill(0.0);
                    }
                    Controller::Agent(p) => p.act(&obs[k * d..(k + 1) * d], rng, row),
                }
            }
        }
        Ok(())
    }
}
