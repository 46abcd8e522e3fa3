//! Built-in metrics: reducers over one run, named in the sweep file's `metrics`. Each becomes one
//! column of the results table (`field_mass` one per pheromone, `time_to_threshold` one per
//! threshold); a value that does not exist in a run (S never halves) is an empty cell.
mod geometry;
mod recorder;

pub use geometry::{clusters, contacts, mean_nearest_neighbour};
pub use recorder::Recorder;

use crate::error::{Result, SweepError};
use crate::spec::{MetricOptions, ThresholdSpec};
use colcos_sim::scenario::Scenario;

/// Every metric: name and formula (the same text as `docs/sweeps.md`).
pub const METRICS: &[(&str, &str)] = [
    (
        "s_mean",
        "mean over the samples of S(t) = sum_i |P_i - P_1| (eq. 9; P_1 the leader, i the followers), m",
    ),
    ("s_final", "S(t) at the last sample, m"),
    (
        "s_halve_time",
        "first sample time t with S(t) <= S(0) / 2, s (empty: never)",
    ),
    (
        "arrivals",
        "robots that came within arrival_radius of any end point (each counted once, at its first)",
    ),
    ("arrivals_food", "robots whose first end point is a food point"),
    ("timeouts", "robots that reached no end point before the run ended"),
    (
        "nn_distance",
        "mean over the samples of (1/N) sum_i min_{j != i} |p_i - p_j|, m",
    ),
    ("nn_distance_final", "the same at the last sample, m"),
    (
        "clusters",
        "connected groups at the last sample, robots linked when |p_i - p_j| <= cluster_distance",
    ),
    (
        "area_covered",
        "fraction of the coverage_cell grid's cells that held a robot's centre at some step",
    ),
    (
        "collisions",
        "robot-robot contacts begun: pairs with |p_i - p_j| < 2 r + contact_margin at a step and not at the step before",
    ),
    (
        "field_mass",
        "per pheromone, at the end: sum over the field grid of Phi h^2 (Gaussian fields evaluated at the cell centres); column field_mass_<name>",
    ),
    (
        "time_to_threshold",
        "per entry of metric_options.thresholds: first sample time the signal is <= below (>= above), s; column time_to_<signal>_<below|above>_<value>",
    ),
]
.as_slice();

/// One metric.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Metric {
    SMean,
    SFinal,
    SHalveTime,
    Arrivals,
    ArrivalsFood,
    Timeouts,
    NnDistance,
    NnDistanceFinal,
    Clusters,
    AreaCovered,
    Collisions,
    FieldMass,
    TimeToThreshold,
}

impl Metric {
    fn parse(name: &str) -> Option<Metric> {
        use Metric::*;
        Some(match name {
            "s_mean" => SMean,
            "s_final" => SFinal,
            "s_halve_time" => SHalveTime,
            "arrivals" => Arrivals,
            "arrivals_food" => ArrivalsFood,
            "timeouts" => Timeouts,
            "nn_distance" => NnDistance,
            "nn_distance_final" => NnDistanceFinal,
            "clusters" => Clusters,
            "area_covered" => AreaCovered,
            "collisions" => Collisions,
            "field_mass" => FieldMass,
            "time_to_threshold" => TimeToThreshold,
            _ => return None,
        })
    }
}

/// What a threshold watches.
#[derive(Clone, Debug, PartialEq)]
pub enum Signal {
    S,
    NnDistance,
    Clusters,
    AreaCovered,
    FieldMass(usize),
}

/// A checked threshold.
#[derive(Clone, Debug)]
pub struct Threshold {
    pub signal: Signal,
    pub value: f64,
    pub below: bool,
    pub column: String,
}

/// The metrics of a sweep, checked against its base scenario.
#[derive(Clone, Debug)]
pub struct MetricSet {
    pub metrics: Vec<Metric>,
    pub options: MetricOptions,
    pub pheromones: Vec<String>,
    pub thresholds: Vec<Threshold>,
    /// Column names, in the order a recorder returns values.
    pub columns: Vec<String>,
}

impl MetricSet {
    /// Checks the names and options; `pheromones` are the base scenario's.
    pub fn new(
        names: &[String],
        options: &MetricOptions,
        pheromones: Vec<String>,
    ) -> Result<MetricSet> {
        if names.is_empty() {
            return Err(SweepError::invalid(
                "metrics",
                "[]",
                format!("name at least one of: {}", metric_names()),
            ));
        }
        let mut metrics = Vec::new();
        for (n, name) in names.iter().enumerate() {
            let m = Metric::parse(name).ok_or_else(|| {
                SweepError::invalid(
                    format!("metrics[{n}]"),
                    format!("\"{name}\""),
                    format!("unknown metric; known: {}", metric_names()),
                )
            })?;
            if metrics.contains(&m) {
                return Err(SweepError::invalid(
                    format!("metrics[{n}]"),
                    format!("\"{name}\""),
                    "named twice",
                ));
            }
            metrics.push(m);
        }
        let o = options;
        let positive = |k: &str, v: f32| {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(SweepError::invalid(
                    format!("metric_options.{k}"),
                    v,
                    "must be a finite number > 0",
                ))
            }
        };
        positive("sample_every", o.sample_every)?;
        positive("cluster_distance", o.cluster_distance)?;
        positive("coverage_cell", o.coverage_cell)?;
        positive("arrival_radius", o.arrival_radius)?;
        if !(o.contact_margin.is_finite() && o.contact_margin >= 0.0) {
            return Err(SweepError::invalid(
                "metric_options.contact_margin",
                o.contact_margin,
                "must be a finite number >= 0",
            ));
        }
        let needs_points = metrics.iter().any(|m| {
            matches!(
                m,
                Metric::Arrivals | Metric::ArrivalsFood | Metric::Timeouts
            )
        });
        if needs_points && o.arrival_points.is_empty() {
            return Err(SweepError::invalid(
                "metric_options.arrival_points",
                "[]",
                "arrivals, arrivals_food and timeouts need the end points [[x, y], ...]",
            ));
        }
        for (n, p) in o.arrival_points.iter().enumerate() {
            if !p.iter().all(|v| v.is_finite()) {
                return Err(SweepError::invalid(
                    format!("metric_options.arrival_points[{n}]"),
                    format!("{p:?}"),
                    "must be finite",
                ));
            }
        }
        for (n, &f) in o.food_points.iter().enumerate() {
            if f == 0 || f > o.arrival_points.len() {
                return Err(SweepError::invalid(
                    format!("metric_options.food_points[{n}]"),
                    f,
                    format!("an end point number, 1..={}", o.arrival_points.len()),
                ));
            }
        }
        let mut thresholds = Vec::new();
        for (n, t) in o.thresholds.iter().enumerate() {
            thresholds.push(check_threshold(n, t, &pheromones)?);
        }
        if metrics.contains(&Metric::TimeToThreshold) && thresholds.is_empty() {
            return Err(SweepError::invalid(
                "metric_options.thresholds",
                "[]",
                "time_to_threshold needs at least one { signal, below | above }",
            ));
        }
        let mut columns = Vec::new();
        for m in &metrics {
            match m {
                Metric::FieldMass => {
                    columns.extend(pheromones.iter().map(|p| format!("field_mass_{p}")))
                }
                Metric::TimeToThreshold => {
                    columns.extend(thresholds.iter().map(|t| t.column.clone()))
                }
                other => columns.push(name_of(*other).to_string()),
            }
        }
        Ok(MetricSet {
            metrics,
            options: options.clone(),
            pheromones,
            thresholds,
            columns,
        })
    }

    pub fn has(&self, m: Metric) -> bool {
        self.metrics.contains(&m)
    }

    /// Checks that a run's scenario has what the metrics read (a leader for S(t)).
    pub fn check_scenario(&self, scenario: &Scenario) -> Result<(), String> {
        let needs_s = self
            .metrics
            .iter()
            .any(|m| matches!(m, Metric::SMean | Metric::SFinal | Metric::SHalveTime))
            || self.thresholds.iter().any(|t| t.signal == Signal::S);
        let has_role = |role: &str| {
            scenario
                .spec
                .robots
                .iter()
                .any(|g| g.role == role && g.count > 0)
        };
        if needs_s && !has_role(&self.options.leader_role) {
            return Err(format!(
                "S(t) needs a robot with role \"{}\" (metric_options.leader_role)",
                self.options.leader_role
            ));
        }
        let names: Vec<&str> = scenario.pheromone_names().collect();
        if (self.has(Metric::FieldMass) || !self.thresholds.is_empty()) && names != self.pheromones
        {
            return Err(format!(
                "field masses need the base scenario's pheromones {:?}, this one has {names:?}",
                self.pheromones
            ));
        }
        Ok(())
    }
}

fn name_of(m: Metric) -> &'static str {
    METRICS
        .iter()
        .map(|(n, _)| *n)
        .find(|n| Metric::parse(n) == Some(m))
        .unwrap_or("?")
}

fn metric_names() -> String {
    METRICS
        .iter()
        .map(|(n, _)| *n)
        .collect::<Vec<_>>()
        .join(", ")
}

fn check_threshold(n: usize, t: &ThresholdSpec, pheromones: &[String]) -> Result<Threshold> {
    let at = |k: &str| format!("metric_options.thresholds[{n}].{k}");
    let signal = match t.signal.as_str() {
        "s" => Signal::S,
        "nn_distance" => Signal::NnDistance,
        "clusters" => Signal::Clusters,
        "area_covered" => Signal::AreaCovered,
        other => match other.strip_prefix("field_mass:") {
            Some(p) => {
                Signal::FieldMass(pheromones.iter().position(|q| q == p).ok_or_else(|| {
                    SweepError::invalid(
                        at("signal"),
                        format!("\"{other}\""),
                        format!("no pheromone `{p}` in the scenario ({pheromones:?})"),
                    )
                })?)
            }
            None => {
                return Err(SweepError::invalid(
                    at("signal"),
                    format!("\"{other}\""),
                    "one of s, nn_distance, clusters, area_covered, field_mass:<pheromone>",
                ));
            }
        },
    };
    let (value, below) = match (t.below, t.above) {
        (Some(v), None) => (v, true),
        (None, Some(v)) => (v, false),
        _ => {
            return Err(SweepError::invalid(
                at("below"),
                format!("{:?} / above = {:?}", t.below, t.above),
                "give exactly one of `below` and `above`",
            ));
        }
    };
    if !value.is_finite() {
        return Err(SweepError::invalid(
            at(if below { "below" } else { "above" }),
            value,
            "must be a finite number",
        ));
    }
    let column = format!(
        "time_to_{}_{}_{}",
        t.signal.replace(':', "_"),
        if below { "below" } else { "above" },
        value
    );
    Ok(Threshold {
        signal,
        value,
        below,
        column,
    })
}
