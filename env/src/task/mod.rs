//! RL tasks: one per file, built by name through [`registry`].
//!
//! A task is the experiment's loop function: unlike a behaviour it sees the whole world (true poses,
//! fields) to hand out rewards and end episodes. Agents still observe only their own sensors.

pub mod aggregation;
pub mod alarm;
pub mod colony;
pub mod coverage;
pub mod external;
pub mod foraging;
pub mod registry;
pub mod trail;

use crate::error::{EnvError, Result};
use colcos_sim::field::Pheromone;
use colcos_sim::scenario::Scenario;
use colcos_sim::world::ArenaView;
use serde::de::DeserializeOwned;

/// A task's memory of one episode of one world (food left, who carries, cells covered): plain
/// counters laid out by the task. The world's [`crate::Episode`] holds it, made afresh by
/// [`Task::initial_state`] at the episode's first step, so it resets with the world and never
/// depends on the number of threads.
pub type TaskState = Vec<u32>;

/// One observation entry a task appends to the agents' 17 sensor values, with its bounds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ExtraObs {
    pub name: &'static str,
    pub low: f32,
    pub high: f32,
}

impl ExtraObs {
    /// A 0-or-1 entry.
    pub const fn flag(name: &'static str) -> Self {
        ExtraObs {
            name,
            low: 0.0,
            high: 1.0,
        }
    }
}

/// An RL problem over a scenario.
pub trait Task: Send + Sync {
    /// Registry name (`"aggregation"`).
    fn name(&self) -> &'static str;
    /// World robot indices of the agents, in agent order. Fixed for the task's lifetime.
    fn agents(&self) -> &[usize];
    /// Prepares a new episode's fields (e.g. brings static maps to steady state). Returns true if it
    /// changed them, so the environment takes one settling step to let the sensors see the change.
    fn on_reset(&self, _pheromones: &mut [Pheromone]) -> bool {
        false
    }
    /// A new episode's [`TaskState`] (empty for a task without memory).
    fn initial_state(&self) -> TaskState {
        Vec::new()
    }
    /// The entries each agent's observation gains after its sensor values (none by default).
    fn extra_observations(&self) -> &'static [ExtraObs] {
        &[]
    }
    /// Writes agent `k`'s extra observation entries (`out`: one per [`Self::extra_observations`]).
    /// `state` is empty before the episode's first step.
    fn observe(&self, _world: &dyn ArenaView, _state: &[u32], _k: usize, _out: &mut [f32]) {}
    /// Writes the step's [`Outcome`] in `world`; `state` is this episode's memory.
    fn evaluate(&self, world: &dyn ArenaView, state: &mut TaskState, out: Outcome<'_>);
    /// Whether [`Self::observe`] or [`Self::evaluate`] read the colour sensors of robots that are
    /// not agents. By default they do not, and the environment skips evaluating the colour of
    /// scripted robots whose behaviour does not read it (`World::skip_unread_colour`): those read 0.
    fn reads_other_robots_colour(&self) -> bool {
        false
    }
}

/// What a task hands out after a step: a reward per agent, and which agents have reached a terminal
/// state (entries only ever set to true, never cleared).
pub struct Outcome<'a> {
    pub rewards: &'a mut [f32],
    pub terminated: &'a mut [bool],
}

/// Deserialises a task's parameter object, naming the key at fault; unknown keys are refused.
pub fn parse_params<T: DeserializeOwned>(task: &str, params: &serde_json::Value) -> Result<T> {
    let value = if params.is_null() {
        serde_json::Value::Object(Default::default())
    } else {
        params.clone()
    };
    serde_path_to_error::deserialize(value).map_err(|e| {
        let path = e.path().to_string();
        let key = if path == "." || path.is_empty() {
            task.to_string()
        } else {
            format!("{task}.{path}")
        };
        EnvError::param(key, e.into_inner().to_string())
    })
}

/// Task `task`'s parameter object, parsed as [`parse_params`] does, and its agents: the robots of
/// the role `role` reads from it, refused as [`require_role`] does under the key `<task>.agent_role`.
pub fn parse_with_agents<P: DeserializeOwned>(
    task: &str,
    scenario: &Scenario,
    params: &serde_json::Value,
    role: impl Fn(&P) -> &str,
) -> Result<(P, Vec<usize>)> {
    let p: P = parse_params(task, params)?;
    let agents = require_role(scenario, role(&p), &format!("{task}.agent_role"))?;
    Ok((p, agents))
}

/// World indices of the robots whose group has role `role`.
pub fn robots_with_role(scenario: &Scenario, role: &str) -> Vec<usize> {
    let mut first = 0;
    let mut out = Vec::new();
    for g in &scenario.spec.robots {
        if g.role == role {
            out.extend(first..first + g.count);
        }
        first += g.count;
    }
    out
}

/// The robots of role `role`, or an error naming the parameter `key` if there are none.
pub fn require_role(scenario: &Scenario, role: &str, key: &str) -> Result<Vec<usize>> {
    let robots = robots_with_role(scenario, role);
    if robots.is_empty() {
        let roles: Vec<&str> = scenario
            .spec
            .robots
            .iter()
            .map(|g| g.role.as_str())
            .collect();
        return Err(EnvError::param(
            key,
            format!("no robot group has role {role:?} in this scenario (roles: {roles:?})"),
        ));
    }
    Ok(robots)
}

/// A finite, non-negative parameter.
pub fn check_non_negative(key: &str, v: f32) -> Result<f32> {
    if v.is_finite() && v >= 0.0 {
        Ok(v)
    } else {
        Err(EnvError::param(key, format!("{v} must be finite and >= 0")))
    }
}

/// A point `q` of parameter `key`, refused unless it lies in the scenario's arena.
pub fn point_in_arena(scenario: &Scenario, key: &str, q: [f32; 2]) -> Result<glam::Vec2> {
    let arena = scenario.arena_size();
    let q = glam::Vec2::from(q);
    if q.is_finite() && q.x >= 0.0 && q.y >= 0.0 && q.x <= arena.x && q.y <= arena.y {
        Ok(q)
    } else {
        Err(EnvError::param(
            key,
            format!("{q} lies outside the arena {arena}"),
        ))
    }
}

/// The points `qs` of parameter `key` (`key[0]`, `key[1]`, ...), each refused unless it lies in the
/// scenario's arena.
pub fn points_in_arena(scenario: &Scenario, key: &str, qs: &[[f32; 2]]) -> Result<Vec<glam::Vec2>> {
    (qs.iter().enumerate())
        .map(|(j, q)| point_in_arena(scenario, &format!("{key}[{j}]"), *q))
        .collect()
}

/// A finite, positive parameter.
pub fn check_positive(key: &str, v: f32) -> Result<f32> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(EnvError::param(key, format!("{v} must be finite and > 0")))
    }
}

/// Brings every grid pheromone with a static injection map and finite evaporation `e` to its steady
/// state `e J` (exact without diffusion). Returns true if any field changed.
pub fn prefill_static_maps(pheromones: &mut [Pheromone]) -> bool {
    let mut changed = false;
    for p in pheromones {
        if let colcos_sim::field::FieldModel::Grid(g) = &mut p.model {
            changed |= g.fill_steady_state();
        }
    }
    changed
}
