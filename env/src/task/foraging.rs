//! Case I of the paper: from the nest, follow the trails to the food that is available now.
//!
//! The long-term trail (blue) leads to every branch end; the short-term attractive trail (green)
//! marks the branches with food; the repellent (red) closes unrewarded branches at their forks. An
//! agent terminates when it reaches a branch end: `+food_reward` at a food end, `-wrong_end_penalty`
//! at any other; every step costs `step_penalty`. At reset the static maps are brought to their
//! steady state `e J` (the paper assumes the trails are already laid).
use super::{Outcome, Task, TaskState, check_non_negative, parse_with_agents, points_in_arena};
use crate::error::{EnvError, Result};
use colcos_sim::field::Pheromone;
use colcos_sim::scenario::Scenario;
use colcos_sim::world::ArenaView;
use glam::Vec2;
use serde::Deserialize;

pub const DESCRIPTION: &str =
    "case I: follow the trails from the nest to the available food, avoid unrewarded ends";
pub const DEFAULT_SCENARIO: &str = include_str!("../../scenarios/foraging.toml");

#[derive(Deserialize)]
#[serde(default, deny_unknown_fields)]
struct Params {
    agent_role: String,
    /// Branch ends with food, m.
    food: Vec<[f32; 2]>,
    /// Branch ends without food, m.
    empty: Vec<[f32; 2]>,
    /// Distance to an end that counts as arriving, m.
    reach_distance: f32,
    food_reward: f32,
    wrong_end_penalty: f32,
    step_penalty: f32,
    /// Start the static maps at their steady state.
    prefill: bool,
}

impl Default for Params {
    /// The ends of the built-in scenario.
    fn default() -> Self {
        Params {
            agent_role: "forager".into(),
            food: vec![[1.3, 0.55]],
            empty: vec![[1.3, 0.7], [1.3, 0.1], [1.3, 0.25]],
            reach_distance: 0.05,
            food_reward: 1.0,
            wrong_end_penalty: 1.0,
            step_penalty: 0.001,
            prefill: true,
        }
    }
}

pub struct Foraging {
    agents: Vec<usize>,
    food: Vec<Vec2>,
    empty: Vec<Vec2>,
    reach_distance: f32,
    food_reward: f32,
    wrong_end_penalty: f32,
    step_penalty: f32,
    prefill: bool,
}

pub fn build(scenario: &Scenario, params: &serde_json::Value) -> Result<Box<dyn Task>> {
    let (p, agents) = parse_with_agents("foraging", scenario, params, |p: &Params| &p.agent_role)?;
    if p.food.is_empty() {
        return Err(EnvError::param(
            "foraging.food",
            "give at least one food end [[x, y], ...]",
        ));
    }
    Ok(Box::new(Foraging {
        agents,
        food: points_in_arena(scenario, "foraging.food", &p.food)?,
        empty: points_in_arena(scenario, "foraging.empty", &p.empty)?,
        reach_distance: check_non_negative("foraging.reach_distance", p.reach_distance)?,
        food_reward: check_non_negative("foraging.food_reward", p.food_reward)?,
        wrong_end_penalty: check_non_negative("foraging.wrong_end_penalty", p.wrong_end_penalty)?,
        step_penalty: check_non_negative("foraging.step_penalty", p.step_penalty)?,
        prefill: p.prefill,
    }))
}

impl Task for Foraging {
    fn name(&self) -> &'static str {
        "foraging"
    }
    fn agents(&self) -> &[usize] {
        &self.agents
    }
    fn on_reset(&self, pheromones: &mut [Pheromone]) -> bool {
        if !self.prefill {
            return false;
        }
        super::prefill_static_maps(pheromones)
    }
    fn evaluate(&self, world: &dyn ArenaView, _state: &mut TaskState, out: Outcome<'_>) {
        let poses = world.poses();
        let r2 = self.reach_distance * self.reach_distance;
        for ((r, t), &i) in out
            .rewards
            .iter_mut()
            .zip(out.terminated.iter_mut())
            .zip(&self.agents)
        {
            let p = poses[i].pos;
            *r = -self.step_penalty;
            if self.food.iter().any(|q| q.distance_squared(p) <= r2) {
                *r += self.food_reward;
                *t = true;
            } else if self.empty.iter().any(|q| q.distance_squared(p) <= r2) {
                *r -= self.wrong_end_penalty;
                *t = true;
            }
        }
    }
}
