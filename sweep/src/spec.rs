//! The sweep file as written: TOML parsed with unknown keys refused and errors naming the key path.
//! [`crate::plan`] turns it into checked runs; `docs/sweeps.md` documents every key.
use crate::error::{Result, SweepError};
use serde::{Deserialize, Serialize};

/// A sweep file.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct SweepSpec {
    /// A label for the tables and plots.
    #[serde(default)]
    pub name: Option<String>,
    /// The base scenario: a path (relative to the sweep file) or an inline table.
    pub scenario: ScenarioRef,
    /// Simulated seconds of every run; default: the scenario's `duration`.
    #[serde(default)]
    pub duration: Option<f32>,
    /// `seeds = N` (seeds 0..N-1) or a list of seeds.
    #[serde(default = "default_seeds")]
    pub seeds: Seeds,
    /// How the axes combine: `grid` (every combination), `latin_hypercube` or `random` (`samples`
    /// points).
    #[serde(default)]
    pub sampling: Sampling,
    /// Points drawn by `latin_hypercube` and `random` sampling.
    #[serde(default)]
    pub samples: Option<usize>,
    /// Seed of the draws that choose axis values (`draw` axes, Latin-hypercube and random sampling).
    #[serde(default)]
    pub sampling_seed: u64,
    /// Static grid fields with no diffusion or wind start at their steady state `e J` and stay there
    /// (case I's trails, built before the robot starts).
    #[serde(default)]
    pub preload_steady_state: bool,
    #[serde(default)]
    pub axes: Vec<AxisSpec>,
    /// Metric names (see [`crate::metrics::METRICS`]).
    pub metrics: Vec<String>,
    #[serde(default)]
    pub metric_options: MetricOptions,
}

fn default_seeds() -> Seeds {
    Seeds::Count(1)
}

/// The base scenario.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(untagged)]
pub enum ScenarioRef {
    Path(String),
    Inline(toml::Table),
}

/// `seeds = N` or `seeds = [..]`.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(untagged)]
pub enum Seeds {
    Count(u64),
    List(Vec<u64>),
}

#[derive(Clone, Copy, Debug, Default, Deserialize, Serialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum Sampling {
    #[default]
    Grid,
    LatinHypercube,
    Random,
}

/// One axis: the scenario key(s) it sets and the values it takes.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct AxisSpec {
    /// A scenario key path (`pheromones[0].evaporation`).
    #[serde(default)]
    pub key: Option<String>,
    /// Several key paths set to the same value (an evaporation that is also carried by emitters).
    #[serde(default)]
    pub keys: Option<Vec<String>>,
    /// Column name in the table; default: the (first) key.
    #[serde(default)]
    pub name: Option<String>,
    /// Explicit values.
    #[serde(default)]
    pub values: Option<Vec<toml::Value>>,
    /// Evenly spaced values.
    #[serde(default)]
    pub range: Option<RangeSpec>,
    /// Random values.
    #[serde(default)]
    pub draw: Option<DrawSpec>,
    /// Round the values to integers (counts).
    #[serde(default)]
    pub integer: bool,
}

/// `range = { from, to, steps, scale = "linear" | "log" }`.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct RangeSpec {
    pub from: f64,
    pub to: f64,
    /// Number of values, ends included (grid sampling).
    #[serde(default)]
    pub steps: Option<usize>,
    #[serde(default)]
    pub scale: Scale,
}

#[derive(Clone, Copy, Debug, Default, Deserialize, Serialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum Scale {
    #[default]
    Linear,
    Log,
}

/// `draw = { distribution, count, ... }`: `uniform` and `log_uniform` take `low`, `high`; `normal`
/// and `log_normal` take `mean`, `sd` (of the logarithm for `log_normal`).
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct DrawSpec {
    pub distribution: Distribution,
    /// Number of draws (grid sampling).
    #[serde(default)]
    pub count: Option<usize>,
    #[serde(default)]
    pub low: Option<f64>,
    #[serde(default)]
    pub high: Option<f64>,
    #[serde(default)]
    pub mean: Option<f64>,
    #[serde(default)]
    pub sd: Option<f64>,
}

#[derive(Clone, Copy, Debug, Deserialize, Serialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum Distribution {
    Uniform,
    LogUniform,
    Normal,
    LogNormal,
}

/// Settings of the metrics; every key has a default.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct MetricOptions {
    /// Seconds between the samples of time-series metrics (S(t), distances, clusters, thresholds).
    pub sample_every: f32,
    /// Role of the robot P_1 of eq. (9).
    pub leader_role: String,
    /// Role of the robots summed over in eq. (9).
    pub follower_role: String,
    /// Robots closer than this (centre to centre, m) are in one cluster.
    pub cluster_distance: f32,
    /// Cell of the coverage grid, m.
    pub coverage_cell: f32,
    /// Two robots are in contact when their centres are closer than a diameter plus this, m.
    pub contact_margin: f32,
    /// End points of case I, m.
    pub arrival_points: Vec<[f32; 2]>,
    /// The end points with food, 1-based indices into `arrival_points`.
    pub food_points: Vec<usize>,
    /// A robot arrives when its centre is this close to an end point, m.
    pub arrival_radius: f32,
    /// End a run once every robot has arrived somewhere.
    pub end_on_arrival: bool,
    /// Thresholds of `time_to_threshold`.
    pub thresholds: Vec<ThresholdSpec>,
}

impl Default for MetricOptions {
    fn default() -> Self {
        MetricOptions {
            sample_every: 0.1,
            leader_role: "leader".into(),
            follower_role: "follower".into(),
            cluster_distance: 0.1,
            coverage_cell: 0.05,
            contact_margin: 0.001,
            arrival_points: Vec::new(),
            food_points: Vec::new(),
            arrival_radius: 0.03,
            end_on_arrival: true,
            thresholds: Vec::new(),
        }
    }
}

/// `{ signal = "s", below = 0.5 }`: the first sample time the signal is at or below (above) the value.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ThresholdSpec {
    /// `s`, `nn_distance`, `clusters`, `area_covered` or `field_mass:<pheromone>`.
    pub signal: String,
    #[serde(default)]
    pub below: Option<f64>,
    #[serde(default)]
    pub above: Option<f64>,
}

/// Parses sweep text; errors name the key path.
pub fn parse(text: &str, file: &str) -> Result<SweepSpec> {
    let parse_err = |message: String| SweepError::Parse {
        file: file.to_string(),
        message,
    };
    let de = toml::de::Deserializer::parse(text).map_err(|e| parse_err(e.to_string()))?;
    serde_path_to_error::deserialize(de).map_err(|e| {
        let path = e.path().to_string();
        let inner = e.into_inner().to_string();
        let inner = inner.trim_end().to_string();
        parse_err(if path == "." || path.is_empty() {
            inner
        } else {
            format!("at `{path}`: {inner}")
        })
    })
}
