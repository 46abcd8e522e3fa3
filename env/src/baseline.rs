//! The hand-written behaviours as baseline policies over a batch: one behaviour per (world, agent),
//! deciding from the same raw sensor readings the agent's observation vector is made of.
use crate::encoding::command_to_action;
use crate::error::{EnvError, Result};
use crate::vec_env::VecEnv;
use colcos_sim::behaviour::{Behaviour, registry};
use colcos_sim::rng::{self, SimRng, Stream};
use colcos_sim::robot::ColiasParams;

pub struct BaselinePolicy {
    name: String,
    params: toml::Table,
    /// The body of the env's robots (the scenario's `[robot]`).
    robot: ColiasParams,
    seed: u64,
    /// Per (world, agent): behaviour, random stream; rebuilt when the world starts a new episode.
    slots: Vec<(Box<dyn Behaviour>, SimRng)>,
    /// (episode, steps) each world was at when its behaviours were last used.
    seen: Vec<(u64, u64)>,
}

impl BaselinePolicy {
    /// Behaviour `name` from the sim registry with `params` (a JSON object), for every agent of `env`.
    pub fn new(env: &VecEnv, name: &str, params: &serde_json::Value, seed: u64) -> Result<Self> {
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
        // Build once to check the name and parameters.
        registry::build_with(name, &params, "baseline", &robot)?;
        let mut policy = BaselinePolicy {
            name: name.into(),
            params,
            robot,
            seed,
            slots: Vec::new(),
            seen: Vec::new(),
        };
        let (e, n) = (env.spec().num_envs, env.spec().num_agents);
        for w in 0..e {
            for i in 0..n {
                policy.slots.push(policy.make(w, i, env.episode(w))?);
            }
            policy.seen.push((env.episode(w), env.episode_steps(w)));
        }
        Ok(policy)
    }

    fn make(&self, w: usize, i: usize, episode: u64) -> Result<(Box<dyn Behaviour>, SimRng)> {
        let b = registry::build_with(&self.name, &self.params, "baseline", &self.robot)?;
        let world = crate::world_slot::world_index(w, episode);
        Ok((b, rng::stream_of(self.seed, world, Stream::Baseline(i))))
    }

    /// Continuous actions `[E, N, 2]` for the env's current observations.
    pub fn act(&mut self, env: &VecEnv, out: &mut [f32]) -> Result<()> {
        let spec = env.spec();
        let (e, n) = (spec.num_envs, spec.num_agents);
        if self.seen.len() != e || out.len() != e * n * 2 {
            return Err(EnvError::Action(format!(
                "baseline policy built for {} worlds; output must hold {} values",
                self.seen.len(),
                e * n * 2
            )));
        }
        for w in 0..e {
            let now = (env.episode(w), env.episode_steps(w));
            if now.0 != self.seen[w].0 || now.1 < self.seen[w].1 {
                for i in 0..n {
                    self.slots[w * n + i] = self.make(w, i, now.0)?;
                }
            }
            self.seen[w] = now;
            let world = env.world(w).expect("w < num_envs");
            let max = world.robot_params().max_wheel_speed;
            for (i, &robot) in spec.agent_robots.iter().enumerate() {
                let (b, rng) = &mut self.slots[w * n + i];
                let cmd = b.act(&world.observations()[robot], rng);
                out[(w * n + i) * 2..(w * n + i) * 2 + 2]
                    .copy_from_slice(&command_to_action(cmd, max));
            }
        }
        Ok(())
    }
}
