//! `alarm`: a scripted predator roams the arena; agents that come near it may lay an alarm
//! pheromone that warns the others.
//!
//! An agent senses the predator only when one lies within `sense_distance` of its centre: its
//! observation gains one entry, `predator_near` (0 or 1), the warning it can pass on by laying
//! `alarm` (red, a grid pheromone of the built-in scenario). An agent is captured in a step when a
//! predator lies within `capture_distance` of its centre. Reward per agent and step, the same for
//! every agent (a team reward):
//!
//! ```text
//! r = safe_reward * (agents not captured this step) / N  -  capture_penalty * [this agent is captured]
//! ```
//!
//! No termination: a captured agent may escape and be safe again. A scenario without a robot of
//! `predator_role` is refused (nothing would threaten the agents).
use super::{
    ExtraObs, Outcome, Task, TaskState, check_non_negative, check_positive, parse_with_agents,
    require_role,
};
use crate::error::{EnvError, Result};
use colcos_sim::scenario::Scenario;
use colcos_sim::world::ArenaView;
use glam::Vec2;
use serde::Deserialize;

pub const DESCRIPTION: &str =
    "stay out of a roaming predator's reach; agents near it may lay an alarm that warns the others";
pub const DEFAULT_SCENARIO: &str = include_str!("../../scenarios/alarm.toml");

const EXTRA: &[ExtraObs] = &[ExtraObs::flag("predator_near")];

#[derive(Deserialize)]
#[serde(default, deny_unknown_fields)]
struct Params {
    agent_role: String,
    predator_role: String,
    /// A predator within this distance captures an agent, m.
    capture_distance: f32,
    /// A predator within this distance sets the agent's `predator_near` entry, m.
    sense_distance: f32,
    safe_reward: f32,
    capture_penalty: f32,
}

impl Default for Params {
    fn default() -> Self {
        Params {
            agent_role: "agent".into(),
            predator_role: "predator".into(),
            capture_distance: 0.1,
            sense_distance: 0.2,
            safe_reward: 1.0,
            capture_penalty: 0.0,
        }
    }
}

pub struct Alarm {
    agents: Vec<usize>,
    predators: Vec<usize>,
    capture2: f32,
    sense2: f32,
    safe_reward: f32,
    capture_penalty: f32,
}

pub fn build(scenario: &Scenario, params: &serde_json::Value) -> Result<Box<dyn Task>> {
    let (p, agents) = parse_with_agents("alarm", scenario, params, |p: &Params| &p.agent_role)?;
    let predators = require_role(scenario, &p.predator_role, "alarm.predator_role")?;
    if predators.iter().any(|i| agents.contains(i)) {
        return Err(EnvError::param(
            "alarm.predator_role",
            "names the agents' own role: the predator must be a scripted robot",
        ));
    }
    let capture = check_positive("alarm.capture_distance", p.capture_distance)?;
    let sense = check_positive("alarm.sense_distance", p.sense_distance)?;
    Ok(Box::new(Alarm {
        agents,
        predators,
        capture2: capture * capture,
        sense2: sense * sense,
        safe_reward: check_non_negative("alarm.safe_reward", p.safe_reward)?,
        capture_penalty: check_non_negative("alarm.capture_penalty", p.capture_penalty)?,
    }))
}

impl Alarm {
    /// Squared distance from `p` to the nearest predator.
    fn nearest2(&self, poses: &[colcos_sim::robot::Pose], p: Vec2) -> f32 {
        (self.predators.iter())
            .map(|&k| poses[k].pos.distance_squared(p))
            .fold(f32::INFINITY, f32::min)
    }
}

impl Task for Alarm {
    fn name(&self) -> &'static str {
        "alarm"
    }
    fn agents(&self) -> &[usize] {
        &self.agents
    }
    fn extra_observations(&self) -> &'static [ExtraObs] {
        EXTRA
    }
    fn observe(&self, world: &dyn ArenaView, _state: &[u32], k: usize, out: &mut [f32]) {
        let poses = world.poses();
        out[0] = (self.nearest2(poses, poses[self.agents[k]].pos) <= self.sense2) as u8 as f32;
    }
    fn evaluate(&self, world: &dyn ArenaView, _state: &mut TaskState, out: Outcome<'_>) {
        let poses = world.poses();
        let mut safe = 0usize;
        for (r, &i) in out.rewards.iter_mut().zip(&self.agents) {
            let captured = self.nearest2(poses, poses[i].pos) <= self.capture2;
            safe += !captured as usize;
            *r = if captured { -self.capture_penalty } else { 0.0 };
        }
        let team = self.safe_reward * safe as f32 / self.agents.len() as f32;
        out.rewards.iter_mut().for_each(|r| *r += team);
    }
}
