//! `summary.json` (the numbers), `summary.md` (the table a person reads, beside the paper) and the
//! console summary, plus the paper's claims as checks.
use super::Report;
use super::case1::{Case1Result, GroupResult};
use super::case2::{Case2Result, Case2Run};
use anyhow::{Context, Result};
use serde::Serialize;
use serde_json::json;
use std::path::{Path, PathBuf};

/// The reading of the paper's case-I claims, measured.
#[derive(Clone, Debug, Serialize)]
pub struct Case1Claims {
    pub g1_at_food: usize,
    pub g2_at_food: usize,
    pub g3_at_food: usize,
    pub trials: usize,
    /// G3: share of trials that end at an available food point.
    pub g3_food_share: f64,
    /// G1: end points with at least one arrival.
    pub g1_distinct_points: usize,
    /// G1: the most arrivals at one end point.
    pub g1_max_at_one_point: usize,
    /// G3 >= 95 % at food.
    pub g3_ok: bool,
    /// G1 over >= 5 end points, none with more than half of the trials.
    pub g1_ok: bool,
    /// G1 < G2 < G3 at food.
    pub g2_ok: bool,
}

impl Case1Claims {
    pub fn all_ok(&self) -> bool {
        self.g1_ok && self.g2_ok && self.g3_ok
    }
}

pub fn case1_claims(r: &Case1Result) -> Case1Claims {
    let foods = &r.config.foods;
    let at = |g: usize| r.groups[g].at_food(foods);
    let trials = r.config.trials;
    let (g1, g2, g3) = (at(0), at(1), at(2));
    let g1c = &r.groups[0].counts;
    let g3_food_share = g3 as f64 / trials.max(1) as f64;
    Case1Claims {
        g1_at_food: g1,
        g2_at_food: g2,
        g3_at_food: g3,
        trials,
        g3_food_share,
        g1_distinct_points: g1c.distinct_points(),
        g1_max_at_one_point: g1c.max_at_one_point(),
        g3_ok: g3_food_share >= 0.95,
        g1_ok: g1c.distinct_points() >= 5 && 2 * g1c.max_at_one_point() <= trials,
        g2_ok: g1 < g2 && g2 < g3,
    }
}

/// The reading of the paper's case-II claims, measured on every run.
#[derive(Clone, Debug, Serialize)]
pub struct Case2Claims {
    /// Per run: the largest relative fall of S over an aggregation phase.
    pub falls: Vec<f32>,
    /// Per run: the largest relative rise of S over a dispersion phase (None: no alarm happened).
    pub rises: Vec<Option<f32>>,
    /// Every run: fall >= 0.5.
    pub fall_ok: bool,
    /// Every run: an alarm happened and rise >= 0.5.
    pub rise_ok: bool,
}

impl Case2Claims {
    pub fn all_ok(&self) -> bool {
        self.fall_ok && self.rise_ok
    }
}

pub fn case2_claims(r: &Case2Result) -> Case2Claims {
    let falls: Vec<f32> = r.runs.iter().map(|x| x.aggregation_fall).collect();
    let rises: Vec<Option<f32>> = r.runs.iter().map(|x| x.alarm_rise).collect();
    Case2Claims {
        fall_ok: falls.iter().all(|&f| f >= 0.5),
        // A run whose predator never came near the prey has no alarm and says nothing about the
        // rise; the claim needs alarms in at least half of the runs, and a rise in every one.
        rise_ok: rises.iter().flatten().all(|&r| r >= 0.5)
            && 2 * rises.iter().flatten().count() >= rises.len(),
        falls,
        rises,
    }
}

fn r3(v: f32) -> f64 {
    (v as f64 * 1000.0).round() / 1000.0
}

/// One group of case I, with food at the end points `foods`.
fn group_json(g: &GroupResult, foods: &[usize]) -> serde_json::Value {
    json!({
        "name": g.name,
        "pheromones": g.pheromones,
        "available_food": foods,
        "arrivals": g.counts.per_point,
        "timeouts": g.counts.timeouts,
        "at_food": g.at_food(foods),
        "trials": g.trials.len(),
    })
}

/// One run of case II.
fn run_json(run: &Case2Run) -> serde_json::Value {
    json!({
        "time": run.times.iter().map(|&t| r3(t)).collect::<Vec<_>>(),
        "s": run.s.iter().map(|&s| r3(s)).collect::<Vec<_>>(),
        "alarm": run.alarm,
        "phases": run.phases,
        "phase_boundaries": run.phases.iter().skip(1).map(|p| r3(p.start)).collect::<Vec<_>>(),
        "aggregation_fall": run.aggregation_fall,
        "alarm_rise": run.alarm_rise,
    })
}

pub fn json(r1: Option<&Case1Result>, r2: Option<&Case2Result>, wall: f64) -> serde_json::Value {
    let case1 = r1.map(|r| {
        let groups: Vec<_> = r
            .groups
            .iter()
            .map(|g| group_json(g, &r.config.foods))
            .collect();
        json!({
            "layout": r.config.layout.name,
            "end_points": r.config.layout.ends.len(),
            "available_food": r.config.foods,
            "trials_per_group": r.config.trials,
            "timeout_s": r.config.timeout,
            "arrival_radius_m": r.config.arrival_radius,
            "seed": r.config.seed,
            "groups": groups,
            "claims": case1_claims(r),
            "wall_seconds": r.wall_seconds,
        })
    });
    let case2 = r2.map(|r| {
        let runs: Vec<_> = r.runs.iter().map(run_json).collect();
        json!({
            "scenario": "scenarios/case2_alarm.toml",
            "seed": r.config.scenario.spec.seed,
            "duration_s": r.config.scenario.spec.duration,
            "sample_every_s": r.config.sample_every,
            "runs": runs,
            "claims": case2_claims(r),
            "wall_seconds": r.wall_seconds,
        })
    });
    json!({ "case1": case1, "case2": case2, "wall_seconds": wall })
}

fn yes(b: bool) -> &'static str {
    if b { "yes" } else { "**no**" }
}

pub fn markdown(r1: Option<&Case1Result>, r2: Option<&Case2Result>, wall: f64) -> String {
    let mut s = String::from("# colcos experiment: the paper's case studies\n\n");
    if let Some(r) = r1 {
        let c = case1_claims(r);
        let n = r.config.layout.ends.len();
        s.push_str(&format!(
            "## Case I: three pheromones in ant foraging\n\nLayout {} ({} end points), available food {:?}, {} trials per group, seed {}, timeout {} s.\n\n",
            r.config.layout.name, n, r.config.foods, r.config.trials, r.config.seed, r.config.timeout
        ));
        s.push_str("| group | pheromones |");
        for k in 1..=n {
            if r.config.foods.contains(&k) {
                s.push_str(&format!(" {k}* |"));
            } else {
                s.push_str(&format!(" {k} |"));
            }
        }
        s.push_str(" timeouts | at food |\n|---|---|");
        s.push_str(&"---|".repeat(n + 2));
        s.push('\n');
        for g in &r.groups {
            s.push_str(&format!("| {} | {} |", g.name, g.pheromones.join(" + ")));
            for v in &g.counts.per_point {
                s.push_str(&format!(" {v} |"));
            }
            s.push_str(&format!(
                " {} | {} |\n",
                g.counts.timeouts,
                g.at_food(&r.config.foods)
            ));
        }
        s.push_str("\n(* = available food)\n\n| claim (paper, Fig. 5) | paper | measured | holds |\n|---|---|---|---|\n");
        s.push_str(&format!(
            "| G3: the robot only arrives at food (>= 95 %) | all 20 trials at food 3 or 10 | {} of {} ({:.0} %) | {} |\n",
            c.g3_at_food,
            c.trials,
            100.0 * c.g3_food_share,
            yes(c.g3_ok)
        ));
        s.push_str(&format!(
            "| G1: arrivals spread (>= 5 end points, none > half) | spread over the end points | {} end points, at most {} at one | {} |\n",
            c.g1_distinct_points,
            c.g1_max_at_one_point,
            yes(c.g1_ok)
        ));
        s.push_str(&format!(
            "| G2 between G1 and G3 at food | G1 < G2 < G3 | {} < {} < {} | {} |\n\n",
            c.g1_at_food,
            c.g2_at_food,
            c.g3_at_food,
            yes(c.g2_ok)
        ));
    }
    if let Some(r) = r2 {
        let c = case2_claims(r);
        s.push_str(&format!(
            "## Case II: aggregation and alarm pheromones\n\n{} runs of `scenarios/case2_alarm.toml`, {} s each, seed {}.\n\n| run | aggregation: S falls by | first alarm at | dispersion: S rises by | phase boundaries (s) |\n|---|---|---|---|---|\n",
            r.runs.len(),
            r.config.scenario.spec.duration,
            r.config.scenario.spec.seed
        ));
        for (k, run) in r.runs.iter().enumerate() {
            let alarm = run
                .phases
                .iter()
                .find(|p| p.kind == colcos_sim::metrics::PhaseKind::Dispersion)
                .map_or("none".to_string(), |p| format!("{:.1} s", p.start));
            let rise = run
                .alarm_rise
                .map_or("none".to_string(), |x| format!("{:.0} %", 100.0 * x));
            let bounds: Vec<String> = run
                .phases
                .iter()
                .skip(1)
                .map(|p| format!("{:.1}", p.start))
                .collect();
            let bounds = if bounds.is_empty() {
                vec!["none".to_string()]
            } else {
                bounds
            };
            s.push_str(&format!(
                "| {k} | {:.0} % | {alarm} | {rise} | {} |\n",
                100.0 * run.aggregation_fall,
                bounds.join(", ")
            ));
        }
        s.push_str(&format!(
            "\nFigs. 7 and 8 show run {} (the first run with an aggregation phase, an alarm and, where a run has one, aggregation again).\n",
            super::moments::featured_run(r)
        ));
        s.push_str("\n| claim (paper, Fig. 8) | paper | measured | holds |\n|---|---|---|---|\n");
        s.push_str(&format!(
            "| S(t) falls by at least half during aggregation | S decays | every run: {} | {} |\n",
            fmt_list(&c.falls),
            yes(c.fall_ok)
        ));
        let rises: Vec<f32> = c.rises.iter().map(|r| r.unwrap_or(f32::NAN)).collect();
        s.push_str(&format!(
            "| S(t) rises by at least half after an alarm | S increases | every run with an alarm (none: the predator never came near; alarms needed in half the runs): {} | {} |\n\n",
            fmt_list(&rises),
            yes(c.rise_ok)
        ));
    }
    s.push_str(&format!(
        "Wall time of the whole experiment: {wall:.2} s.\n"
    ));
    s
}

fn fmt_list(v: &[f32]) -> String {
    v.iter()
        .map(|x| {
            if x.is_nan() {
                "none".into()
            } else {
                format!("{:.0} %", 100.0 * x)
            }
        })
        .collect::<Vec<_>>()
        .join(", ")
}

/// Writes summary.json and summary.md into `out`.
pub fn write(
    out: &Path,
    r1: Option<&Case1Result>,
    r2: Option<&Case2Result>,
    wall: f64,
) -> Result<Vec<PathBuf>> {
    let j = out.join("summary.json");
    let text =
        serde_json::to_string_pretty(&json(r1, r2, wall)).context("serialising the summary")?;
    std::fs::write(&j, text + "\n").with_context(|| format!("writing {}", j.display()))?;
    let m = out.join("summary.md");
    std::fs::write(&m, markdown(r1, r2, wall))
        .with_context(|| format!("writing {}", m.display()))?;
    Ok(vec![j, m])
}

/// A few lines for the terminal.
pub fn console(report: &Report) -> String {
    let mut s = String::new();
    if let Some(r) = &report.case1 {
        let c = case1_claims(r);
        for g in &r.groups {
            s.push_str(&format!(
                "case I  {}: arrivals {:?}, timeouts {}, at food {:?}: {}\n",
                g.name,
                g.counts.per_point,
                g.counts.timeouts,
                r.config.foods,
                g.at_food(&r.config.foods)
            ));
        }
        s.push_str(&format!(
            "case I  claims: G3 >= 95 % {}, G1 spread {}, G1 < G2 < G3 {}\n",
            c.g3_ok, c.g1_ok, c.g2_ok
        ));
    }
    if let Some(r) = &report.case1_random {
        s.push_str(&super::random_run::markdown(r));
    }
    if let Some(r) = &report.case2 {
        let c = case2_claims(r);
        s.push_str(&format!(
            "case II aggregation falls {}, alarm rises {}\n",
            fmt_list(&c.falls),
            fmt_list(
                &c.rises
                    .iter()
                    .map(|r| r.unwrap_or(f32::NAN))
                    .collect::<Vec<_>>()
            )
        ));
        s.push_str(&format!(
            "case II claims: fall >= 50 % {}, rise >= 50 % {}\n",
            c.fall_ok, c.rise_ok
        ));
    }
    s
}
