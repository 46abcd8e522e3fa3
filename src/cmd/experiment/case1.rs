//! Case I: three pheromones in ant foraging. Groups G1 (LAP), G2 (LAP + SAP), G3 (LAP + SAP + SRP),
//! `trials` trials each; one robot per trial starting at the nest; a trial ends when the robot comes
//! within `arrival_radius` of an end point, or times out.
//!
//! The paper builds the trails before the robot starts ("the pheromone branches have been constructed
//! already"), so the scenarios pre-load the steady state `e J` at t = 0 (`preload = true`).
//! Speed-up (exact): with `d = 0`, `Phi = e J` stays there for ever (`Phi <- a Phi + e (1 - a) J =
//! e J`), so every trial freezes the grid (no evaporation, no injection), which leaves the same field
//! without stepping 140,000 cells per time step.
use super::layout::TrailLayout;
use anyhow::Result;
use colcos_sim::behaviour::WheelCommand;
use colcos_sim::field::FieldModel;
use colcos_sim::metrics::{ArrivalCounts, TrialOutcome, arrival};
use colcos_sim::prelude::*;

/// The three groups: name and pheromones.
pub const GROUPS: [(&str, &[&str]); 3] = [
    ("G1", &["LAP"]),
    ("G2", &["LAP", "SAP"]),
    ("G3", &["LAP", "SAP", "SRP"]),
];

#[derive(Clone, Debug)]
pub struct Case1Config {
    pub layout: TrailLayout,
    /// Available food points, 1-based end point numbers.
    pub foods: Vec<usize>,
    pub trials: usize,
    pub seed: u64,
    /// Time limit of a trial, s.
    pub timeout: f32,
    /// A trial ends when the robot's centre is this close to an end point, m.
    pub arrival_radius: f32,
    /// Field grid cell, m.
    pub cell: f32,
    /// Keep one position every this many steps in the trajectories.
    pub trajectory_every: u64,
    /// Parameters of the `forage` behaviour (Algorithm 1); empty: its defaults.
    pub forage: toml::Table,
}

impl Case1Config {
    pub fn new(layout: TrailLayout, trials: usize, seed: u64) -> Self {
        let foods = layout.default_foods();
        Case1Config {
            layout,
            foods,
            trials,
            seed,
            timeout: 60.0,
            arrival_radius: 0.03,
            cell: 0.005,
            trajectory_every: 5,
            forage: toml::Table::new(),
        }
    }

    /// The scenario of group `g` (0, 1, 2 for G1, G2, G3).
    pub fn scenario(&self, g: usize) -> Result<Scenario> {
        let mut spec =
            self.layout
                .scenario_spec(&self.foods, GROUPS[g].1, self.seed, self.timeout, self.cell);
        spec.robots[0].params = self.forage.clone();
        Ok(Scenario::from_spec(spec, ".")?)
    }
}

/// One trial: how it ended and the path (true positions).
#[derive(Clone, Debug)]
pub struct Trial {
    pub outcome: TrialOutcome,
    pub path: Vec<Vec2>,
}

#[derive(Clone, Debug)]
pub struct GroupResult {
    pub name: String,
    pub pheromones: Vec<String>,
    pub trials: Vec<Trial>,
    pub counts: ArrivalCounts,
}

impl GroupResult {
    /// Arrivals at the available food points.
    pub fn at_food(&self, foods: &[usize]) -> usize {
        let idx: Vec<usize> = foods.iter().map(|f| f - 1).collect();
        self.counts.at(&idx)
    }
}

#[derive(Clone, Debug)]
pub struct Case1Result {
    pub config: Case1Config,
    pub groups: Vec<GroupResult>,
    pub wall_seconds: f64,
}

/// Freezes every pre-loaded static grid field (already at its steady state `e J`, which stepping
/// would keep): no injection, no evaporation.
pub fn freeze_steady_state(world: &mut World, scenario: &Scenario) {
    for (p, spec) in world
        .pheromones_mut()
        .iter_mut()
        .zip(&scenario.spec.pheromones)
    {
        if !spec.preload {
            continue;
        }
        if let FieldModel::Grid(g) = &mut p.model {
            g.freeze();
        }
    }
}

/// Runs one trial of `scenario` (world index `trial`).
pub fn run_trial(
    scenario: &Scenario,
    trial: usize,
    ends: &[Vec2],
    radius: f32,
    every: u64,
) -> Result<Trial> {
    let mut world = World::with_index(scenario, trial as u64)?;
    freeze_steady_state(&mut world, scenario);
    // One still step so that the first observation the robot acts on sees the loaded trails.
    world.step_with_commands(&[WheelCommand::STOP]);
    let mut path = vec![world.poses()[0].pos];
    let steps = scenario.steps();
    let every = every.max(1);
    for k in 1..=steps {
        world.step();
        let p = world.poses()[0].pos;
        if k.is_multiple_of(every) {
            path.push(p);
        }
        if let Some(point) = arrival(p, ends, radius) {
            path.push(p);
            return Ok(Trial {
                outcome: TrialOutcome::Arrived {
                    point,
                    time: world.time(),
                },
                path,
            });
        }
    }
    Ok(Trial {
        outcome: TrialOutcome::TimedOut,
        path,
    })
}

/// The (group, trial) tasks of case I, for a shared progress count.
pub fn task_count(cfg: &Case1Config) -> usize {
    GROUPS.len() * cfg.trials
}

/// Runs every trial of every group in parallel; results are gathered by (group, trial) index, so
/// they do not depend on the thread count. `tick` is called once per finished trial.
pub fn run(cfg: &Case1Config, tick: &(dyn Fn() + Sync)) -> Result<Case1Result> {
    let started = std::time::Instant::now();
    let scenarios: Vec<Scenario> = (0..GROUPS.len())
        .map(|g| cfg.scenario(g))
        .collect::<Result<_>>()?;
    let ends = cfg.layout.end_points();
    let tasks: Vec<(usize, usize)> = (0..GROUPS.len())
        .flat_map(|g| (0..cfg.trials).map(move |t| (g, t)))
        .collect();
    let results: Vec<Result<Trial>> = super::par_map_ticking(&tasks, tick, |&(g, t)| {
        run_trial(
            &scenarios[g],
            t,
            &ends,
            cfg.arrival_radius,
            cfg.trajectory_every,
        )
    });
    let mut groups: Vec<GroupResult> = GROUPS
        .iter()
        .map(|(name, ph)| GroupResult {
            name: name.to_string(),
            pheromones: ph.iter().map(|s| s.to_string()).collect(),
            trials: Vec::new(),
            counts: ArrivalCounts::default(),
        })
        .collect();
    for (&(g, _), r) in tasks.iter().zip(results) {
        groups[g].trials.push(r?);
    }
    for g in &mut groups {
        let outcomes: Vec<TrialOutcome> = g.trials.iter().map(|t| t.outcome).collect();
        g.counts = ArrivalCounts::tally(&outcomes, ends.len());
    }
    Ok(Case1Result {
        config: cfg.clone(),
        groups,
        wall_seconds: started.elapsed().as_secs_f64(),
    })
}

/// `group,pheromones,end_point,food,arrivals` rows, then one `group,pheromones,timeout,0,n` row per
/// group.
pub fn arrivals_csv(r: &Case1Result) -> String {
    let mut w = super::csv_writer(&["group", "pheromones", "end_point", "food", "arrivals"]);
    for g in &r.groups {
        let ph = g.pheromones.join("+");
        for (k, n) in g.counts.per_point.iter().enumerate() {
            let food = r.config.foods.contains(&(k + 1));
            let point = (k + 1).to_string();
            let row: [&str; 5] = [&g.name, &ph, &point, food_flag(food), &n.to_string()];
            w.write_record(row).expect("writing to memory");
        }
        let timeouts = g.counts.timeouts.to_string();
        w.write_record([g.name.as_str(), &ph, "timeout", "0", &timeouts])
            .expect("writing to memory");
    }
    super::csv_text(w)
}

/// One row per trial: group, trial, end point (or empty on timeout), time.
pub fn trials_csv(r: &Case1Result) -> String {
    let mut w = super::csv_writer(&["group", "trial", "end_point", "food", "time"]);
    for g in &r.groups {
        for (t, trial) in g.trials.iter().enumerate() {
            let t = t.to_string();
            let row = match trial.outcome {
                TrialOutcome::Arrived { point, time } => {
                    let food = r.config.foods.contains(&(point + 1));
                    let point = (point + 1).to_string();
                    [
                        g.name.clone(),
                        t,
                        point,
                        food_flag(food).into(),
                        format!("{time:.2}"),
                    ]
                }
                TrialOutcome::TimedOut => [
                    g.name.clone(),
                    t,
                    String::new(),
                    "0".into(),
                    format!("{:.2}", r.config.timeout),
                ],
            };
            w.write_record(&row).expect("writing to memory");
        }
    }
    super::csv_text(w)
}

/// The `food` column: 1 where the end point is a food source.
fn food_flag(food: bool) -> &'static str {
    if food { "1" } else { "0" }
}
