//! `colony_ant`: the classic two-pheromone ant rule for the `colony` task.
//!
//! Searching (not carrying), an agent lays `home` and follows a `food` trail where it finds one,
//! steering to keep it between its left and right sensors, and away from the nest's glow; loaded, it
//! lays `food` and follows `home` trails and the glow back. Picking up and delivering turn it about
//! (ants reverse at the food and at the nest), which puts it on the trail it has just laid. Off any
//! trail it walks at random. Expects the built-in scenario's channels (home red, food green, nest
//! blue) and deposit actions (food, then home), and the carrying flag at entry 17.
use super::{AgentPolicy, Walker, down_gradient_angle, gradient_angle, level, steer, strength};
use colcos_sim::rng::SimRng;

const HOME: usize = 0;
const FOOD: usize = 1;
const NEST: usize = 2;
/// Mean intensity above which a trail counts as found.
const TRAIL: f32 = 0.04;
/// Mean nest glow above which a loaded agent climbs it.
const GLOW: f32 = 0.02;
/// Forward speed, fraction of the top speed.
const SPEED: f32 = 0.5;
/// Steps of the turn about at a pick-up or delivery (about 180 degrees at the pivot speed).
const ABOUT: u32 = 29;

#[derive(Default)]
pub struct ColonyAnt {
    walker: Walker,
    carrying: bool,
}

/// Wheels that keep a trail of channel `c` between the left and right sensors.
fn along(obs: &[f32], c: usize) -> (f32, f32) {
    let turn = (1.5 * (level(obs, 2, c) - level(obs, 0, c))).clamp(-0.15, 0.15);
    (SPEED - turn, SPEED + turn)
}

impl AgentPolicy for ColonyAnt {
    fn act(&mut self, obs: &[f32], rng: &mut SimRng, out: &mut [f32]) {
        let carrying = obs.get(17).is_some_and(|&c| c > 0.5);
        if carrying != self.carrying {
            self.carrying = carrying;
            self.walker.start_pivot(ABOUT, 1.0);
        }
        // Lay food while loaded, home while searching.
        if out.len() >= 4 {
            out[2] = carrying as u8 as f32;
            out[3] = !carrying as u8 as f32;
        }
        let (l, r) = if let Some(w) = self.walker.avoid(obs) {
            w
        } else if carrying && strength(obs, NEST) > GLOW {
            steer(SPEED, gradient_angle(obs, NEST), 0.1)
        } else if carrying && strength(obs, HOME) > TRAIL {
            along(obs, HOME)
        } else if !carrying && strength(obs, FOOD) > TRAIL {
            let (l, r) = along(obs, FOOD);
            // Leave the nest behind: the food trail leads away from it.
            let away = if strength(obs, NEST) > TRAIL {
                (0.05 * down_gradient_angle(obs, NEST)).clamp(-0.1, 0.1)
            } else {
                0.0
            };
            (l - away, r + away)
        } else {
            self.walker.walk(SPEED, rng)
        };
        (out[0], out[1]) = self.walker.drive((l, r));
    }
}
