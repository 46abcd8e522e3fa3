//! `colony`: central-place foraging with two pheromones the agents choose to lay.
//!
//! A nest and food patches of finite food. An agent that is not carrying and whose centre comes
//! within `food_radius` of a patch with food left picks one unit up (the patch loses it); an agent
//! carrying one unit that comes within `nest_radius` of the nest delivers it. Each agent's
//! observation gains one entry, `carrying` (0 or 1). Reward per agent and step:
//!
//! ```text
//! r_k = delivery_reward * (units delivered by the whole team this step)
//!     + pickup_reward * [agent k picked a unit up this step]
//!     - step_penalty
//! ```
//!
//! No termination (episodes end by truncation); once every patch is empty only the units still
//! carried can pay. Agents pick up and deliver in agent order, so the last unit of a patch goes to
//! the lowest agent index that reaches it in that step. In the built-in scenario the agents may lay
//! `food` (green) and `home` (red) trails; the nest glows blue (a fixed Gaussian source).
use super::{
    ExtraObs, Outcome, Task, TaskState, check_non_negative, check_positive, parse_with_agents,
    point_in_arena, points_in_arena,
};
use crate::error::{EnvError, Result};
use colcos_sim::scenario::Scenario;
use colcos_sim::world::ArenaView;
use glam::Vec2;
use serde::Deserialize;

pub const DESCRIPTION: &str = "central-place foraging: carry food from finite patches to the nest, laying food and home trails";
pub const DEFAULT_SCENARIO: &str = include_str!("../../scenarios/colony.toml");

const EXTRA: &[ExtraObs] = &[ExtraObs::flag("carrying")];

#[derive(Deserialize)]
#[serde(default, deny_unknown_fields)]
struct Params {
    agent_role: String,
    /// Centre of the nest, m.
    nest: [f32; 2],
    /// m.
    nest_radius: f32,
    /// Centres of the food patches, m.
    food: Vec<[f32; 2]>,
    /// m.
    food_radius: f32,
    /// Units of food in each patch at the start of an episode.
    food_amount: u32,
    delivery_reward: f32,
    pickup_reward: f32,
    step_penalty: f32,
}

impl Default for Params {
    /// The nest and patches of the built-in scenario.
    fn default() -> Self {
        Params {
            agent_role: "agent".into(),
            nest: [0.25, 0.405],
            nest_radius: 0.08,
            food: vec![[1.15, 0.65], [1.15, 0.16]],
            food_radius: 0.07,
            food_amount: 10,
            delivery_reward: 1.0,
            pickup_reward: 0.0,
            step_penalty: 0.0,
        }
    }
}

pub struct Colony {
    agents: Vec<usize>,
    nest: Vec2,
    nest_radius: f32,
    food: Vec<Vec2>,
    food_radius: f32,
    food_amount: u32,
    delivery_reward: f32,
    pickup_reward: f32,
    step_penalty: f32,
}

/// The layout of a colony episode's [`TaskState`]: food left in each patch, then each agent's
/// carrying flag, then the units delivered so far.
#[derive(Clone, Copy, Debug)]
pub struct Layout {
    pub patches: usize,
    pub agents: usize,
}

impl Layout {
    /// Units left in patch `j`.
    pub fn food_left(&self, state: &[u32], j: usize) -> u32 {
        state.get(j).copied().unwrap_or(0)
    }
    /// Whether agent `k` carries a unit.
    pub fn carrying(&self, state: &[u32], k: usize) -> bool {
        state.get(self.patches + k).is_some_and(|&c| c != 0)
    }
    /// Units delivered in the episode so far.
    pub fn delivered(&self, state: &[u32]) -> u32 {
        state.get(self.patches + self.agents).copied().unwrap_or(0)
    }
}

pub fn build(scenario: &Scenario, params: &serde_json::Value) -> Result<Box<dyn Task>> {
    Ok(Box::new(Colony::new(scenario, params)?))
}

impl Colony {
    pub fn new(scenario: &Scenario, params: &serde_json::Value) -> Result<Self> {
        let (p, agents) =
            parse_with_agents("colony", scenario, params, |p: &Params| &p.agent_role)?;
        if p.food.is_empty() {
            return Err(EnvError::param(
                "colony.food",
                "give at least one food patch [[x, y], ...]",
            ));
        }
        if p.food_amount == 0 {
            return Err(EnvError::param("colony.food_amount", "must be at least 1"));
        }
        Ok(Colony {
            agents,
            nest: point_in_arena(scenario, "colony.nest", p.nest)?,
            nest_radius: check_positive("colony.nest_radius", p.nest_radius)?,
            food: points_in_arena(scenario, "colony.food", &p.food)?,
            food_radius: check_positive("colony.food_radius", p.food_radius)?,
            food_amount: p.food_amount,
            delivery_reward: check_non_negative("colony.delivery_reward", p.delivery_reward)?,
            pickup_reward: check_non_negative("colony.pickup_reward", p.pickup_reward)?,
            step_penalty: check_non_negative("colony.step_penalty", p.step_penalty)?,
        })
    }

    /// How this task lays out its episode memory.
    pub fn layout(&self) -> Layout {
        Layout {
            patches: self.food.len(),
            agents: self.agents.len(),
        }
    }
}

impl Task for Colony {
    fn name(&self) -> &'static str {
        "colony"
    }
    fn agents(&self) -> &[usize] {
        &self.agents
    }
    fn initial_state(&self) -> TaskState {
        let mut state = vec![self.food_amount; self.food.len()];
        state.resize(self.food.len() + self.agents.len() + 1, 0);
        state
    }
    fn extra_observations(&self) -> &'static [ExtraObs] {
        EXTRA
    }
    fn observe(&self, _world: &dyn ArenaView, state: &[u32], k: usize, out: &mut [f32]) {
        out[0] = self.layout().carrying(state, k) as u8 as f32;
    }
    fn evaluate(&self, world: &dyn ArenaView, state: &mut TaskState, out: Outcome<'_>) {
        let poses = world.poses();
        let patches = self.food.len();
        let (nest2, food2) = (self.nest_radius.powi(2), self.food_radius.powi(2));
        let mut delivered = 0u32;
        for (k, (r, &i)) in out.rewards.iter_mut().zip(&self.agents).enumerate() {
            let p = poses[i].pos;
            *r = -self.step_penalty;
            let carry = patches + k;
            if state[carry] != 0 {
                if p.distance_squared(self.nest) <= nest2 {
                    state[carry] = 0;
                    delivered += 1;
                }
            } else if let Some(j) =
                (0..patches).find(|&j| state[j] > 0 && p.distance_squared(self.food[j]) <= food2)
            {
                state[j] -= 1;
                state[carry] = 1;
                *r += self.pickup_reward;
            }
        }
        state[patches + self.agents.len()] += delivered;
        if delivered > 0 {
            let team = self.delivery_reward * delivered as f32;
            out.rewards.iter_mut().for_each(|r| *r += team);
        }
    }
}
