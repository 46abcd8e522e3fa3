//! Follow and lay a trail: agents are rewarded for driving forward along a colour trail (a static loop
//! in the built-in scenario), while laying trails of their own that others can follow.
//!
//! Reward per agent and step: `forward speed / max speed * strength of channel` (its own sensors'
//! mean intensity), minus `bump_penalty * strongest bumper`. No termination.
//!
//! `maze = true` runs the loop as a walled corridor (the built-in `trail_maze` scenario: an island and
//! an outer wall, `[[obstacles]]`); the bumper penalty then also counts the walls.
use super::{Outcome, Task, TaskState, check_non_negative, parse_params, require_role};
use crate::error::{EnvError, Result};
use colcos_sim::channel::Channel;
use colcos_sim::field::Pheromone;
use colcos_sim::scenario::Scenario;
use colcos_sim::world::ArenaView;
use serde::Deserialize;

pub const DESCRIPTION: &str =
    "follow a colour trail forward while laying one (static loop plus the robots' own trails)";
pub const DEFAULT_SCENARIO: &str = include_str!("../../scenarios/trail.toml");
/// The built-in scenario with `maze = true`.
pub const MAZE_SCENARIO: &str = include_str!("../../scenarios/trail_maze.toml");

/// The built-in scenario `params` ask for (`maze = true`: the walled corridor); a malformed `maze`
/// falls back to the plain loop and [`build`] reports it.
pub fn default_scenario(params: &serde_json::Value) -> &'static str {
    match params.get("maze") {
        Some(serde_json::Value::Bool(true)) => MAZE_SCENARIO,
        _ => DEFAULT_SCENARIO,
    }
}

#[derive(Deserialize)]
#[serde(default, deny_unknown_fields)]
struct Params {
    agent_role: String,
    /// Channel of the trail to follow: "r", "g" or "b".
    channel: Channel,
    bump_penalty: f32,
    /// The walled corridor: the built-in `trail_maze` scenario, or a scenario of one's own that
    /// lists `[[obstacles]]`.
    maze: bool,
}

impl Default for Params {
    fn default() -> Self {
        Params {
            agent_role: "agent".into(),
            channel: Channel::B,
            bump_penalty: 0.1,
            maze: false,
        }
    }
}

pub struct Trail {
    agents: Vec<usize>,
    channel: usize,
    bump_penalty: f32,
    inv_max_speed: f32,
}

pub fn build(scenario: &Scenario, params: &serde_json::Value) -> Result<Box<dyn Task>> {
    let p: Params = parse_params("trail", params)?;
    if p.maze && scenario.spec.obstacles.is_empty() {
        return Err(EnvError::param(
            "trail.maze",
            format!(
                "true, but scenario {:?} lists no [[obstacles]] (use the built-in scenario or add walls)",
                scenario.spec.name
            ),
        ));
    }
    let agents = require_role(scenario, &p.agent_role, "trail.agent_role")?;
    let channel = p.channel.index();
    let max = scenario.spec.robot.max_wheel_speed;
    Ok(Box::new(Trail {
        agents,
        channel,
        bump_penalty: check_non_negative("trail.bump_penalty", p.bump_penalty)?,
        inv_max_speed: if max > 0.0 { 1.0 / max } else { 0.0 },
    }))
}

impl Task for Trail {
    fn name(&self) -> &'static str {
        "trail"
    }
    fn agents(&self) -> &[usize] {
        &self.agents
    }
    fn on_reset(&self, pheromones: &mut [Pheromone]) -> bool {
        super::prefill_static_maps(pheromones)
    }
    fn evaluate(&self, world: &dyn ArenaView, _state: &mut TaskState, out: Outcome<'_>) {
        let obs = world.observations();
        let params = world.robot_params();
        for (r, &i) in out.rewards.iter_mut().zip(&self.agents) {
            let (forward, _) = world.robots()[i].drive.body_velocity(params);
            let o = &obs[i];
            *r = forward * self.inv_max_speed * o.strength(self.channel)
                - self.bump_penalty * o.max_bumper();
        }
    }
}
