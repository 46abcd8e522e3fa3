//! Case II of the paper: followers gather at the leader (aggregation pheromone, green, emitted by the
//! leader) and flee the alarm (red, emitted by any prey robot near the predator).
//!
//! Reward per follower and step (docs/python.md, "Training"):
//!
//! ```text
//! r = progress_weight * (v . g) / max_wheel_speed * (1 - strongest bumper)
//!   - distance_weight * d(leader) / arena diagonal
//!   - alarm_weight * A(p)
//!   - capture_penalty * [a predator within capture_distance]
//! ```
//!
//! `v` is the follower's own velocity (forward speed along its heading), `A(p)` the screen level (0..1)
//! of the alarm channel (red) at its position, and `g` its goal direction as in Algorithm 3: straight
//! down the alarm gradient while `A(p) > alarm_threshold` (the alarm phase: flee), else toward the
//! leader (the aggregation phase: gather). The first term is dense and depends on the follower's own
//! action only, which is what makes the task learnable in minutes; the others are the state's cost.
//! No termination: episodes end by truncation.
use super::{Outcome, Task, TaskState, check_non_negative, parse_with_agents, require_role};
use crate::error::Result;
use colcos_sim::channel::Channel;
use colcos_sim::scenario::Scenario;
use colcos_sim::world::ArenaView;
use glam::Vec2;
use serde::Deserialize;

pub const DESCRIPTION: &str =
    "case II: followers gather at the leader and flee the alarm near the predator";
pub const DEFAULT_SCENARIO: &str = include_str!("../../scenarios/aggregation.toml");

/// Step of the central differences that give the alarm gradient of a grid pheromone, m (Gaussian
/// sources give theirs analytically).
const GRADIENT_STEP: f32 = 0.005;

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
    /// Weight of the progress along the goal direction (own velocity, fraction of the top speed).
    progress_weight: f32,
    /// Weight of the alarm level at the follower's position.
    alarm_weight: f32,
    /// Alarm level (0..1) above which a follower is in the alarm phase (the followers' default).
    alarm_threshold: f32,
    /// Screen channel of the alarm pheromone: "r", "g" or "b".
    alarm_channel: Channel,
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
            progress_weight: 1.0,
            alarm_weight: 1.0,
            alarm_threshold: 0.05,
            alarm_channel: Channel::R,
        }
    }
}

pub struct Aggregation {
    agents: Vec<usize>,
    leader: usize,
    predators: Vec<usize>,
    /// The parameters as given, each weight and distance checked.
    p: Params,
    alarm_channel: usize,
    inv_diagonal: f32,
}

pub fn build(scenario: &Scenario, params: &serde_json::Value) -> Result<Box<dyn Task>> {
    let (p, agents) =
        parse_with_agents("aggregation", scenario, params, |p: &Params| &p.agent_role)?;
    let leader = require_role(scenario, &p.leader_role, "aggregation.leader_role")?[0];
    // A scenario without a predator is allowed: pure aggregation.
    let predators = super::robots_with_role(scenario, &p.predator_role);
    for (key, v) in [
        ("capture_distance", p.capture_distance),
        ("capture_penalty", p.capture_penalty),
        ("distance_weight", p.distance_weight),
        ("progress_weight", p.progress_weight),
        ("alarm_weight", p.alarm_weight),
        ("alarm_threshold", p.alarm_threshold),
    ] {
        check_non_negative(&format!("aggregation.{key}"), v)?;
    }
    Ok(Box::new(Aggregation {
        agents,
        leader,
        predators,
        alarm_channel: p.alarm_channel.index(),
        p,
        inv_diagonal: 1.0 / scenario.arena_size().length().max(1e-6),
    }))
}

/// Screen level (0..1, not clamped) of channel `c` at `p`, the sum over pheromones of
/// `colour_c * value`, and its gradient (analytic for Gaussian sources: one `exp` per source).
fn level_and_gradient(world: &dyn ArenaView, c: usize, p: Vec2) -> (f32, Vec2) {
    world
        .pheromones()
        .iter()
        .enumerate()
        .filter(|(_, ph)| ph.colour[c] != 0.0)
        .fold((0.0, Vec2::ZERO), |(level, grad), (index, ph)| {
            let k = ph.colour[c] / 255.0;
            let (v, g) = world.pheromone_value_and_gradient_observed(index, p, GRADIENT_STEP);
            (level + k * v, grad + k * g)
        })
}

impl Task for Aggregation {
    fn name(&self) -> &'static str {
        "aggregation"
    }
    fn agents(&self) -> &[usize] {
        &self.agents
    }
    fn evaluate(&self, world: &dyn ArenaView, _state: &mut TaskState, out: Outcome<'_>) {
        let poses = world.poses();
        let robots = world.robots();
        let obs = world.observations();
        let params = world.robot_params();
        let inv_max_speed = if params.max_wheel_speed > 0.0 {
            1.0 / params.max_wheel_speed
        } else {
            0.0
        };
        let leader = poses[self.leader].pos;
        let c2 = self.p.capture_distance * self.p.capture_distance;
        let c = self.alarm_channel;
        for (r, &i) in out.rewards.iter_mut().zip(&self.agents) {
            let p = poses[i].pos;
            let to_leader = leader - p;
            let d = to_leader.length();
            let (alarm, grad) = level_and_gradient(world, c, p);
            let goal = if alarm > self.p.alarm_threshold {
                -grad.normalize_or_zero()
            } else {
                to_leader.normalize_or_zero()
            };
            let (forward, _) = robots[i].drive.body_velocity(params);
            let velocity = world.forward(i) * forward;
            let free = (1.0 - obs[i].max_bumper()).clamp(0.0, 1.0);
            let progress = (velocity.dot(goal) * inv_max_speed).clamp(-1.0, 1.0) * free;
            let mut reward = self.p.progress_weight * progress
                - self.p.distance_weight * d * self.inv_diagonal
                - self.p.alarm_weight * alarm.min(1.0);
            if self
                .predators
                .iter()
                .any(|&k| poses[k].pos.distance_squared(p) < c2)
            {
                reward -= self.p.capture_penalty;
            }
            *r = reward;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use colcos_sim::behaviour::WheelCommand;
    use colcos_sim::scenario::{EmitSpec, PheromoneSpec, RobotGroupSpec, ScenarioBuilder};
    use colcos_sim::world::World;

    /// Leader at (1.0, 0.4), one follower at (0.5, 0.4) with heading `heading` (degrees) driving forward
    /// for 10 steps; with `predator`, the predator is next to the leader, which makes the leader release
    /// the alarm pheromone, else in a far corner.
    fn reward_after(heading: f32, predator: bool) -> f32 {
        let avoid_at = |role: &str, pose: [f32; 3]| {
            RobotGroupSpec::new(1, "avoid")
                .with_role(role)
                .at_poses(vec![pose])
        };
        // Far from everyone (no alarm), or next to the leader.
        let predator_at = if predator { [1.1, 0.4] } else { [0.1, 0.75] };
        let scenario = ScenarioBuilder::new()
            .name("t")
            .screen([384, 216], [1.439, 0.809])
            .pheromone(PheromoneSpec::gaussian("agp", [0.0, 255.0, 0.0]).with_evaporation(10.0))
            .pheromone(PheromoneSpec::gaussian("alp", [255.0, 0.0, 0.0]).with_evaporation(5.0))
            .robots(
                avoid_at("leader", [1.0, 0.4, 0.0])
                    .with_emit(EmitSpec::follow("agp", 0.7884, [0.4, 0.4], 10.0))
                    .with_emit(
                        EmitSpec::follow("alp", 1.7740, [0.6, 0.6], 5.0).when_near("predator", 0.2),
                    ),
            )
            .robots(avoid_at("follower", [0.5, 0.4, heading]))
            .robots(avoid_at("predator", [predator_at[0], predator_at[1], 0.0]))
            .build()
            .unwrap();
        let task = build(&scenario, &serde_json::Value::Null).unwrap();
        let mut world = World::new(&scenario).unwrap();
        let mut commands = vec![WheelCommand::STOP; world.robot_count()];
        commands[1] = WheelCommand::new(0.2, 0.2);
        for _ in 0..10 {
            world.step_with_commands(&commands);
        }
        let mut rewards = [0.0];
        let out = Outcome {
            rewards: &mut rewards,
            terminated: &mut [false],
        };
        task.evaluate(&world, &mut Vec::new(), out);
        rewards[0]
    }

    #[test]
    fn driving_toward_the_leader_pays_when_calm() {
        let (toward, away) = (reward_after(0.0, false), reward_after(180.0, false));
        assert!(toward > away + 0.5, "toward {toward}, away {away}");
    }

    #[test]
    fn driving_away_from_the_alarm_pays_in_the_alarm_phase() {
        // The alarm source is at the leader: fleeing it now means driving away from the leader.
        let (toward, away) = (reward_after(0.0, true), reward_after(180.0, true));
        assert!(away > toward + 0.5, "toward {toward}, away {away}");
    }
}
