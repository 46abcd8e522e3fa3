//! Case II of the paper: followers gather at the leader (aggregation pheromone, green, emitted by the
//! leader) and flee the alarm (red, emitted by any prey robot near the predator).
//!
//! Reward per follower and step: `-distance_weight * d(leader) / arena diagonal`, minus
//! `capture_penalty` while a predator is within `capture_distance`. No termination: episodes end by
//! truncation.
use super::{Task, check_non_negative, parse_params, require_role};
use crate::error::Result;
use colcos_sim::scenario::Scenario;
use colcos_sim::world::World;
use serde::Deserialize;

pub const DESCRIPTION: &str =
    "case II: followers gather at the leader and flee the alarm near the predator";
pub const DEFAULT_SCENARIO: &str = include_str!("../../scenarios/aggregation.toml");

#[derive(Deserialize)]
#[serde(default, deny_unknown_fields)]
struct Params {
    /// Role of the learning robots.
    agent_role: String,
    leader_role: String,
    predator_role: String,
    /// m.
    capture_distance: f32,
    capture_penalty: f32,
    distance_weight: f32,
}

impl Default for Params {
    fn default() -> Self {
        Params {
            agent_role: "follower".into(),
            leader_role: "leader".into(),
            predator_role: "predator".into(),
            capture_distance: 0.1,
            capture_penalty: 1.0,
            distance_weight: 1.0,
        }
    }
}

pub struct Aggregation {
    agents: Vec<usize>,
    leader: usize,
    predators: Vec<usize>,
    capture_distance: f32,
    capture_penalty: f32,
    distance_weight: f32,
    inv_diagonal: f32,
}

pub fn build(scenario: &Scenario, params: &serde_json::Value) -> Result<Box<dyn Task>> {
    let p: Params = parse_params("aggregation", params)?;
    let agents = require_role(scenario, &p.agent_role, "aggregation.agent_role")?;
    let leader = require_role(scenario, &p.leader_role, "aggregation.leader_role")?[0];
    // A scenario without a predator is allowed: pure aggregation.
    let predators = super::robots_with_role(scenario, &p.predator_role);
    Ok(Box::new(Aggregation {
        agents,
        leader,
        predators,
        capture_distance: check_non_negative("aggregation.capture_distance", p.capture_distance)?,
        capture_penalty: check_non_negative("aggregation.capture_penalty", p.capture_penalty)?,
        distance_weight: check_non_negative("aggregation.distance_weight", p.distance_weight)?,
        inv_diagonal: 1.0 / scenario.arena_size().length().max(1e-6),
    }))
}

impl Task for Aggregation {
    fn name(&self) -> &'static str {
        "aggregation"
    }
    fn agents(&self) -> &[usize] {
        &self.agents
    }
    fn evaluate(&self, world: &World, rewards: &mut [f32], _terminated: &mut [bool]) {
        let poses = world.poses();
        let leader = poses[self.leader].pos;
        let c2 = self.capture_distance * self.capture_distance;
        for (r, &i) in rewards.iter_mut().zip(&self.agents) {
            let p = poses[i].pos;
            let mut reward = -self.distance_weight * p.distance(leader) * self.inv_diagonal;
            if self
                .predators
                .iter()
                .any(|&k| poses[k].pos.distance_squared(p) < c2)
            {
                reward -= self.capture_penalty;
            }
            *r = reward;
        }
    }
}
