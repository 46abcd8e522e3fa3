//! `alarm_flee`: the `alarm` task's baseline (case II's follower with a self-laid alarm).
//!
//! An agent that senses the predator (`predator_near`, entry 17) lays `alarm` and runs straight on
//! at full speed; one that reads alarm flees down its gradient; otherwise it keeps still, which
//! draws no predator toward it. Bumps turn it away as in every baseline.
use super::{AgentPolicy, Walker, down_gradient_angle, steer, strength};
use colcos_sim::rng::SimRng;

/// The alarm channel of the built-in scenario (red).
const ALARM: usize = 0;
/// Mean intensity above which an agent reads alarm.
const ALERT: f32 = 0.03;

#[derive(Default)]
pub struct AlarmFlee {
    walker: Walker,
}

impl AgentPolicy for AlarmFlee {
    fn act(&mut self, obs: &[f32], _rng: &mut SimRng, out: &mut [f32]) {
        let near = obs.get(17).is_some_and(|&v| v > 0.5);
        out[2..].fill(near as u8 as f32);
        let (l, r) = if let Some(w) = self.walker.avoid(obs) {
            w
        } else if strength(obs, ALARM) > ALERT {
            steer(1.0, down_gradient_angle(obs, ALARM), 0.1)
        } else if near {
            (1.0, 1.0)
        } else {
            (0.0, 0.0)
        };
        (out[0], out[1]) = self.walker.drive((l, r));
    }
}
