//! `coverage_walk`: the `coverage` task's baseline, a random walk that avoids the pheromone.
//!
//! The agent always lays `visited` (its only deposit action) and walks at random; where its sensors
//! read `visited` it steers down the trail's gradient, into ground nobody has marked. Its own fresh
//! trail lies behind it, so that gradient pushes it on rather than turning it.
use super::{AgentPolicy, Walker, down_gradient_angle, steer, strength};
use colcos_sim::rng::SimRng;

/// The visited channel of the built-in scenario (green).
const VISITED: usize = 1;
/// Mean intensity above which the agent reads a trail.
const SEEN: f32 = 0.05;
const SPEED: f32 = 0.6;

#[derive(Default)]
pub struct CoverageWalk {
    walker: Walker,
}

impl AgentPolicy for CoverageWalk {
    fn act(&mut self, obs: &[f32], rng: &mut SimRng, out: &mut [f32]) {
        out[2..].fill(1.0);
        let (l, r) = if let Some(w) = self.walker.avoid(obs) {
            w
        } else if strength(obs, VISITED) > SEEN {
            steer(SPEED, down_gradient_angle(obs, VISITED), 0.15)
        } else {
            self.walker.walk(SPEED, rng)
        };
        (out[0], out[1]) = self.walker.drive((l, r));
    }
}
