//! `python`: a task whose rewards, terminations and extra observations are computed outside Rust,
//! by a `colcos.Task` written in Python, once per batched step over every world (see
//! `VecEnv::step_deferred` and `VecEnv::conclude`). Here only the agents are chosen: the robots
//! whose group has role `agent_role`.
use super::{Outcome, Task, TaskState, parse_with_agents};
use crate::error::Result;
use colcos_sim::field::Pheromone;
use colcos_sim::scenario::Scenario;
use colcos_sim::world::ArenaView;
use serde::Deserialize;

pub const NAME: &str = "python";

pub const DESCRIPTION: &str =
    "a task written in Python (colcos.Task): its hooks hand out rewards and terminations";

#[derive(Deserialize)]
#[serde(default, deny_unknown_fields)]
struct Params {
    agent_role: String,
    /// Start the static maps at their steady state (as the built-in tasks do).
    prefill: bool,
}

impl Default for Params {
    fn default() -> Self {
        Params {
            agent_role: "agent".into(),
            prefill: true,
        }
    }
}

pub struct External {
    agents: Vec<usize>,
    prefill: bool,
}

pub fn build(scenario: &Scenario, params: &serde_json::Value) -> Result<Box<dyn Task>> {
    let (p, agents) = parse_with_agents(NAME, scenario, params, |p: &Params| &p.agent_role)?;
    Ok(Box::new(External {
        agents,
        prefill: p.prefill,
    }))
}

impl Task for External {
    fn name(&self) -> &'static str {
        NAME
    }
    fn agents(&self) -> &[usize] {
        &self.agents
    }
    fn on_reset(&self, pheromones: &mut [Pheromone]) -> bool {
        self.prefill && super::prefill_static_maps(pheromones)
    }
    /// Nothing of its own: a deferred step's rewards and terminations are given to
    /// `VecEnv::conclude`; a plain step hands out none.
    fn evaluate(&self, _world: &dyn ArenaView, _state: &mut TaskState, out: Outcome<'_>) {
        out.rewards.fill(0.0);
    }
}
