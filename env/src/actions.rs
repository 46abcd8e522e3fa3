//! Actions, decoded once for every environment of a task (the batch's worlds and the plants' arena),
//! with one set of error texts: the wheels of each agent and, where its group declares
//! `deposit_actions`, how much of each of those pheromones it lays this step.
//!
//! Continuous: each agent's row is `[left, right, rate_0, .., rate_{D-1}]`, wheels as fractions of
//! the largest wheel speed in `[-1, 1]`, rates as fractions of each deposit action's `max_rate` in
//! `[0, 1]` (values beyond are clamped; non-finite ones refused). Discrete: one integer per agent,
//! `motion + 6 * lay_bits`, where `motion` is one of the six [`encoding::DISCRETE_ACTIONS`] and bit
//! `d` of `lay_bits` lays pheromone action `d` at its full rate: `6 * 2^D` actions.
use crate::encoding::{self, DISCRETE_ACTIONS};
use crate::error::{EnvError, Result};
use colcos_sim::behaviour::WheelCommand;
use colcos_sim::scenario::Scenario;

/// A batch's actions, `[E, N, 2 + D]` floats or `[E, N]` integers, flat.
#[derive(Clone, Copy, Debug)]
pub enum Actions<'a> {
    Continuous(&'a [f32]),
    Discrete(&'a [i64]),
}

/// Turns a batch's actions into wheel commands and deposit rate fractions.
#[derive(Clone, Debug)]
pub struct ActionDecoder {
    discrete: bool,
    agents: usize,
    /// Deposit actions per agent (`D`).
    deposits: usize,
    max_speed: f32,
}

impl ActionDecoder {
    pub fn new(discrete: bool, agents: usize, deposits: usize, max_speed: f32) -> Self {
        ActionDecoder {
            discrete,
            agents,
            deposits,
            max_speed,
        }
    }

    /// Entries of one agent's continuous action: two wheels and one rate per deposit action.
    pub fn width(&self) -> usize {
        2 + self.deposits
    }

    /// Deposit actions per agent.
    pub fn deposits(&self) -> usize {
        self.deposits
    }

    /// Number of discrete actions: each of the six motions with each choice of pheromones to lay.
    pub fn discrete_count(&self) -> usize {
        DISCRETE_ACTIONS.len() << self.deposits
    }

    /// Decodes `worlds` worlds' actions into `commands` (`[E, N]`) and `rates` (`[E, N, D]`, rate
    /// fractions in `[0, 1]`). Nothing is written unless every action is valid.
    pub fn decode(
        &self,
        actions: Actions,
        worlds: usize,
        commands: &mut [WheelCommand],
        rates: &mut [f32],
    ) -> Result<()> {
        let (e, n, d) = (worlds, self.agents, self.deposits);
        debug_assert_eq!(commands.len(), e * n);
        debug_assert_eq!(rates.len(), e * n * d);
        let max = self.max_speed;
        match (actions, self.discrete) {
            (Actions::Continuous(a), false) => {
                let w = self.width();
                if a.len() != e * n * w {
                    return Err(EnvError::Action(format!(
                        "expected {} values (num_envs {e} x agents {n} x {}), got {}",
                        e * n * w,
                        self.row_words(),
                        a.len()
                    )));
                }
                if let Some(k) = a.iter().position(|v| !v.is_finite()) {
                    let (world, agent, c) = (k / (w * n), (k / w) % n, k % w);
                    return Err(EnvError::Action(format!(
                        "action of world {world}, agent robot_{agent}, {} is {} (must be finite)",
                        self.entry_name(c),
                        a[k]
                    )));
                }
                for (k, (cmd, row)) in commands.iter_mut().zip(a.chunks_exact(w)).enumerate() {
                    *cmd = encoding::continuous_command(row[0], row[1], max);
                    for (out, v) in rates[k * d..(k + 1) * d].iter_mut().zip(&row[2..]) {
                        *out = v.clamp(0.0, 1.0);
                    }
                }
            }
            (Actions::Discrete(a), true) => {
                if a.len() != e * n {
                    return Err(EnvError::Action(format!(
                        "expected {} actions (num_envs {e} x agents {n}), got {}",
                        e * n,
                        a.len()
                    )));
                }
                let count = self.discrete_count();
                if let Some(k) = a.iter().position(|&v| v < 0 || v >= count as i64) {
                    return Err(EnvError::Action(format!(
                        "action of world {}, agent robot_{} is {}, not in 0..{count}",
                        k / n,
                        k % n,
                        a[k]
                    )));
                }
                let motions = DISCRETE_ACTIONS.len() as i64;
                for (k, (cmd, &v)) in commands.iter_mut().zip(a).enumerate() {
                    *cmd =
                        encoding::discrete_command(v % motions, max).unwrap_or(WheelCommand::STOP);
                    let bits = v / motions;
                    for (j, out) in rates[k * d..(k + 1) * d].iter_mut().enumerate() {
                        *out = ((bits >> j) & 1) as f32;
                    }
                }
            }
            (Actions::Continuous(_), true) => {
                return Err(EnvError::Action(
                    "this environment has discrete actions (integers), got continuous ones".into(),
                ));
            }
            (Actions::Discrete(_), false) => {
                return Err(EnvError::Action(format!(
                    "this environment has continuous actions (floats, [.., {}]), got discrete ones",
                    self.width()
                )));
            }
        }
        Ok(())
    }

    fn row_words(&self) -> String {
        match self.deposits {
            0 => "2 wheels".into(),
            d => format!("(2 wheels + {d} deposit rates)"),
        }
    }

    fn entry_name(&self, c: usize) -> String {
        match c {
            0 | 1 => format!("wheel {c}"),
            c => format!("deposit rate {}", c - 2),
        }
    }
}

/// Deposit actions per agent (trails, then emitters switched by action: see
/// `RobotGroupSpec::action_pheromones`): every agent's group declares the same number, and only
/// agents' groups declare any (a scripted robot could not choose its rates).
pub(crate) fn deposit_actions_per_agent(scenario: &Scenario, agents: &[usize]) -> Result<usize> {
    let mut first = 0;
    let mut per_agent: Option<(usize, usize)> = None;
    for (g, group) in scenario.spec.robots.iter().enumerate() {
        let d = group.action_count();
        let range = first..first + group.count;
        first += group.count;
        let is_agent = agents.iter().any(|i| range.contains(i));
        let key = format!("robots[{g}].deposit_actions");
        if !is_agent {
            if d > 0 {
                let emits = d > group.deposit_actions.len();
                return Err(EnvError::param(
                    if emits {
                        format!("robots[{g}].emits")
                    } else {
                        key
                    },
                    if emits {
                        "an emitter with `when = \"action\"` on robots that are not agents of the \
                         task: nothing would switch it (use `follow` or `near`)"
                    } else {
                        "this group's robots are not agents of the task, so nothing would choose \
                         their rates (give them `deposits` instead)"
                    },
                ));
            }
            continue;
        }
        match per_agent {
            None => per_agent = Some((g, d)),
            Some((h, e)) if e != d => {
                return Err(EnvError::param(
                    key,
                    format!(
                        "{d} deposit actions (trails and emitters switched by action), but the \
                         agents of robots[{h}] have {e}: every agent of a task takes actions of \
                         one width"
                    ),
                ));
            }
            Some(_) => {}
        }
    }
    Ok(per_agent.map_or(0, |(_, d)| d))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn discrete_actions_are_motions_times_lay_bits() {
        let dec = ActionDecoder::new(true, 1, 2, 0.1);
        assert_eq!(dec.discrete_count(), 24);
        let (mut cmd, mut rates) = ([WheelCommand::STOP], [0.0; 2]);
        // Forward (1) laying pheromone 1 only: 1 + 6 * 0b10.
        dec.decode(Actions::Discrete(&[13]), 1, &mut cmd, &mut rates)
            .unwrap();
        assert_eq!(cmd[0], encoding::discrete_command(1, 0.1).unwrap());
        assert_eq!(rates, [0.0, 1.0]);
        let err = dec
            .decode(Actions::Discrete(&[24]), 1, &mut cmd, &mut rates)
            .unwrap_err();
        assert!(err.to_string().contains("not in 0..24"), "{err}");
    }

    #[test]
    fn continuous_rates_are_clamped_and_named_when_not_finite() {
        let dec = ActionDecoder::new(false, 2, 1, 0.1);
        let (mut cmd, mut rates) = ([WheelCommand::STOP; 2], [0.0; 2]);
        dec.decode(
            Actions::Continuous(&[0.5, 0.5, 2.0, 0.0, 0.0, -1.0]),
            1,
            &mut cmd,
            &mut rates,
        )
        .unwrap();
        assert_eq!(rates, [1.0, 0.0]);
        let err = dec
            .decode(
                Actions::Continuous(&[0.5, 0.5, 0.2, 0.0, 0.0, f32::NAN]),
                1,
                &mut cmd,
                &mut rates,
            )
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("agent robot_1, deposit rate 0 is NaN"),
            "{err}"
        );
        let err = dec
            .decode(Actions::Continuous(&[0.5; 4]), 1, &mut cmd, &mut rates)
            .unwrap_err()
            .to_string();
        assert!(err.contains("(2 wheels + 1 deposit rates)"), "{err}");
    }
}
