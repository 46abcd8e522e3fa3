//! `coverage`: the team explores the arena, and may mark where it has been with a `visited` trail.
//!
//! The arena is cut into square cells of side `cell` (a coarse grid, the last row and column
//! possibly narrower). A cell is covered the first time any agent's centre lies in it during the
//! episode (the cells the agents start in count at the first step). Reward per agent and step, the
//! same for every agent:
//!
//! ```text
//! r = cell_reward * (cells covered for the first time this step, by the whole team)
//!   - bump_penalty * (the agent's strongest bumper)
//! ```
//!
//! so an episode's team return is `cell_reward` times the cells covered (minus the bumps): each
//! cell pays once per episode. No termination. The observation has no extra entry: the only memory
//! of where the team has been is what it lays.
use super::{Outcome, Task, TaskState, check_non_negative, check_positive, parse_with_agents};
use crate::error::{EnvError, Result};
use colcos_sim::scenario::Scenario;
use colcos_sim::world::ArenaView;
use serde::Deserialize;

pub const DESCRIPTION: &str =
    "cover the arena as a team (reward per new cell), marking where it has been with a trail";
pub const DEFAULT_SCENARIO: &str = include_str!("../../scenarios/coverage.toml");

/// Most cells of the grid: a finer grid is a per-pixel map, not a coarse coverage count.
const MAX_CELLS: usize = 1 << 16;

#[derive(Deserialize)]
#[serde(default, deny_unknown_fields)]
struct Params {
    agent_role: String,
    /// Side of a grid cell, m.
    cell: f32,
    cell_reward: f32,
    bump_penalty: f32,
}

impl Default for Params {
    fn default() -> Self {
        Params {
            agent_role: "agent".into(),
            cell: 0.05,
            cell_reward: 1.0,
            bump_penalty: 0.0,
        }
    }
}

pub struct Coverage {
    agents: Vec<usize>,
    cell: f32,
    cols: usize,
    rows: usize,
    cell_reward: f32,
    bump_penalty: f32,
}

pub fn build(scenario: &Scenario, params: &serde_json::Value) -> Result<Box<dyn Task>> {
    Ok(Box::new(Coverage::new(scenario, params)?))
}

impl Coverage {
    pub fn new(scenario: &Scenario, params: &serde_json::Value) -> Result<Self> {
        let (p, agents) =
            parse_with_agents("coverage", scenario, params, |p: &Params| &p.agent_role)?;
        let cell = check_positive("coverage.cell", p.cell)?;
        let arena = scenario.arena_size();
        let (cols, rows) = (
            (arena.x / cell).ceil().max(1.0) as usize,
            (arena.y / cell).ceil().max(1.0) as usize,
        );
        if cols.saturating_mul(rows) > MAX_CELLS {
            return Err(EnvError::param(
                "coverage.cell",
                format!(
                    "{cell} m cuts the arena into {cols} x {rows} cells, more than {MAX_CELLS}"
                ),
            ));
        }
        Ok(Coverage {
            agents,
            cell,
            cols,
            rows,
            cell_reward: check_non_negative("coverage.cell_reward", p.cell_reward)?,
            bump_penalty: check_non_negative("coverage.bump_penalty", p.bump_penalty)?,
        })
    }

    /// Cells of the grid.
    pub fn cells(&self) -> usize {
        self.cols * self.rows
    }

    /// Cells covered so far in an episode whose memory is `state`.
    pub fn covered(&self, state: &[u32]) -> u32 {
        state.get(self.cells()).copied().unwrap_or(0)
    }
}

impl Task for Coverage {
    fn name(&self) -> &'static str {
        "coverage"
    }
    fn agents(&self) -> &[usize] {
        &self.agents
    }
    /// One flag per cell, then the count of covered cells.
    fn initial_state(&self) -> TaskState {
        vec![0; self.cells() + 1]
    }
    fn evaluate(&self, world: &dyn ArenaView, state: &mut TaskState, out: Outcome<'_>) {
        let poses = world.poses();
        let obs = world.observations();
        let inv = 1.0 / self.cell;
        let mut new = 0u32;
        for &i in &self.agents {
            let p = poses[i].pos;
            // A robot pushed onto the edge counts in the edge cell.
            let c = ((p.x * inv).max(0.0) as usize).min(self.cols - 1);
            let r = ((p.y * inv).max(0.0) as usize).min(self.rows - 1);
            let flag = &mut state[r * self.cols + c];
            if *flag == 0 {
                *flag = 1;
                new += 1;
            }
        }
        let count = self.cells();
        state[count] += new;
        let team = self.cell_reward * new as f32;
        for (r, &i) in out.rewards.iter_mut().zip(&self.agents) {
            *r = team - self.bump_penalty * obs[i].max_bumper();
        }
    }
}
