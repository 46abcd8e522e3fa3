//! A sweep file turned into runs: the combinations of axis values (a grid, a Latin hypercube or random
//! points), times the seeds. Run `id = combo * seeds + seed index`. Each run's scenario is the base
//! scenario's TOML with the axis values set at their key paths, the seed and the duration, parsed and
//! validated by the scenario code, so every scenario check applies to every combination; a failure names
//! the sweep file, the axis, its key and value ([`crate::explain`]).
use crate::axis::{Axis, unit};
use crate::error::{Result, SweepError};
use crate::metrics::MetricSet;
use crate::spec::{Sampling, ScenarioRef, Seeds, SweepSpec, parse};
use colcos_sim::error::SimError;
use colcos_sim::rng;
use colcos_sim::scenario::Scenario;
use rayon::prelude::*;
use std::path::{Path, PathBuf};

/// Fixed columns before the axes, and between the axes and the metrics.
pub const ID_COLUMNS: [&str; 2] = ["run_id", "combo"];
pub const SEED_COLUMN: &str = "seed";
pub const WALL_COLUMN: &str = "wall_s";

/// A checked sweep, ready to run.
#[derive(Clone, Debug)]
pub struct Plan {
    pub name: String,
    pub spec: SweepSpec,
    pub axes: Vec<Axis>,
    /// One value per axis for each combination.
    pub combos: Vec<Vec<toml::Value>>,
    pub seeds: Vec<u64>,
    pub metrics: MetricSet,
    /// The results table's header.
    pub columns: Vec<String>,
    /// A hash of everything that decides the table: a directory's table is resumed only by the same.
    pub fingerprint: String,
    /// Metric columns computed outside this crate (Python callables), after the built-in ones.
    pub extra_metrics: Vec<String>,
    /// The sweep file, as errors name it.
    pub file: String,
    base: toml::Table,
    scenario_dir: PathBuf,
}

impl Plan {
    /// Reads a sweep file; a base scenario path is relative to it.
    pub fn from_file(path: impl AsRef<Path>) -> Result<Plan> {
        let path = path.as_ref();
        let text = std::fs::read_to_string(path)
            .map_err(|e| SweepError::io(format!("reading sweep file {}", path.display()), e))?;
        let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
        Self::from_toml_str(&text, &path.display().to_string(), &dir)
    }

    /// Parses sweep text; `dir` resolves the base scenario's path (`file` names it in errors).
    pub fn from_toml_str(text: &str, file: &str, dir: &Path) -> Result<Plan> {
        Self::checked(text, file, dir).map_err(|e| e.in_file(file))
    }

    fn checked(text: &str, file: &str, dir: &Path) -> Result<Plan> {
        let spec = parse(text, file)?;
        let (base, scenario_dir, base_text) = match &spec.scenario {
            ScenarioRef::Path(p) => {
                let path = dir.join(p);
                let base_err = |source| SweepError::Base {
                    path: path.display().to_string(),
                    source,
                };
                let text = std::fs::read_to_string(&path).map_err(|e| {
                    base_err(SimError::io(format!("reading {}", path.display()), e))
                })?;
                let table: toml::Table = text.parse().map_err(|e: toml::de::Error| {
                    base_err(SimError::Parse {
                        path: path.display().to_string(),
                        message: e.to_string(),
                    })
                })?;
                let sdir = path.parent().map(Path::to_path_buf).unwrap_or_default();
                (table, sdir, text)
            }
            ScenarioRef::Inline(t) => (t.clone(), dir.to_path_buf(), t.to_string()),
        };
        if let Some(d) = spec.duration
            && !(d.is_finite() && d > 0.0)
        {
            return Err(SweepError::invalid(
                "duration",
                d,
                "must be a finite number > 0",
            ));
        }
        let seeds = match &spec.seeds {
            Seeds::Count(0) => return Err(SweepError::invalid("seeds", 0, "at least one seed")),
            Seeds::Count(n) => (0..*n).collect(),
            Seeds::List(l) if l.is_empty() => {
                return Err(SweepError::invalid("seeds", "[]", "at least one seed"));
            }
            Seeds::List(l) => {
                for (n, s) in l.iter().enumerate() {
                    if l[..n].contains(s) {
                        return Err(SweepError::invalid(
                            format!("seeds[{n}]"),
                            s,
                            "listed twice",
                        ));
                    }
                }
                l.clone()
            }
        };
        let axes = spec
            .axes
            .iter()
            .enumerate()
            .map(|(i, a)| Axis::from_spec(i, a))
            .collect::<Result<Vec<_>>>()?;
        for (i, a) in axes.iter().enumerate() {
            if let Some(j) = axes[..i].iter().position(|b| b.name == a.name) {
                return Err(SweepError::invalid(
                    format!("axes[{i}].name"),
                    format!("\"{}\"", a.name),
                    format!("the same column name as axes[{j}]; give one a `name`"),
                ));
            }
        }
        check_distinct_keys(&axes)?;
        for (i, a) in axes.iter().enumerate() {
            let metric = crate::metrics::METRICS.iter().any(|(m, _)| *m == a.name);
            let fixed = ID_COLUMNS.contains(&a.name.as_str())
                || a.name == SEED_COLUMN
                || a.name == WALL_COLUMN;
            if metric
                || fixed
                || a.name.starts_with("field_mass_")
                || a.name.starts_with("time_to_")
            {
                return Err(SweepError::invalid(
                    format!("axes[{i}].name"),
                    format!("\"{}\"", a.name),
                    "the name of a fixed or metric column of the table; give the axis another `name`",
                ));
            }
        }
        let combos = combinations(&spec, &axes)?;
        let name = spec.name.clone().unwrap_or_else(|| {
            Path::new(file)
                .file_stem()
                .map_or("sweep".into(), |s| s.to_string_lossy().into_owned())
        });
        let mut plan = Plan {
            name,
            metrics: MetricSet::new(&spec.metrics, &spec.metric_options, Vec::new())?,
            spec,
            axes,
            combos,
            seeds,
            columns: Vec::new(),
            fingerprint: String::new(),
            extra_metrics: Vec::new(),
            file: file.to_string(),
            base,
            scenario_dir,
        };
        // The pheromone names of field masses come from the first combination's scenario.
        let first = plan.build(0, false)?;
        let pheromones = first.pheromone_names().map(String::from).collect();
        plan.metrics = MetricSet::new(&plan.spec.metrics, &plan.spec.metric_options, pheromones)?;
        plan.columns = ID_COLUMNS.iter().map(|s| s.to_string()).collect();
        plan.columns
            .extend(plan.axes.iter().map(|a| a.name.clone()));
        plan.columns.push(SEED_COLUMN.into());
        plan.columns.extend(plan.metrics.columns.iter().cloned());
        plan.columns.push(WALL_COLUMN.into());
        for (k, c) in plan.columns.iter().enumerate() {
            if plan.columns[..k].contains(c) {
                return Err(SweepError::invalid(
                    "axes",
                    format!("\"{c}\""),
                    "a column name used twice (an axis named like a metric or a fixed column)",
                ));
            }
        }
        let spec_text = toml::to_string(&plan.spec).unwrap_or_default();
        plan.fingerprint = format!(
            "{:016x}",
            fnv1a(&[
                spec_text.as_bytes(),
                base_text.as_bytes(),
                plan.columns.join(",").as_bytes()
            ])
        );
        Ok(plan)
    }

    /// The same sweep with metric columns computed elsewhere (after the built-in metrics, before
    /// `wall_s`); they take part in the fingerprint, so a table is resumed only with the same ones.
    pub fn with_extra_metrics(mut self, names: &[String]) -> Result<Plan> {
        for (n, name) in names.iter().enumerate() {
            let bad = name.is_empty() || name.contains([',', '"', '\n', '\r']);
            if bad || self.columns.contains(name) || names[..n].contains(name) {
                return Err(SweepError::invalid(
                    format!("metrics (extra) [{n}]"),
                    format!("\"{name}\""),
                    "a new column name: not empty, no commas, quotes or line breaks, not used twice",
                ));
            }
        }
        let wall = self.columns.pop().unwrap_or_else(|| WALL_COLUMN.into());
        self.columns.extend(names.iter().cloned());
        self.columns.push(wall);
        self.extra_metrics = names.to_vec();
        self.fingerprint = format!(
            "{:016x}",
            fnv1a(&[
                self.fingerprint.as_bytes(),
                self.columns.join(",").as_bytes()
            ])
        );
        Ok(self)
    }

    /// The directory the base scenario's relative paths (image maps) resolve against.
    pub fn scenario_dir(&self) -> &Path {
        &self.scenario_dir
    }

    /// The sweep as self-contained TOML, the base scenario inlined: what a worker elsewhere rebuilds
    /// the same runs from (with [`Plan::scenario_dir`] as its directory).
    pub fn portable_toml(&self) -> String {
        let mut spec = self.spec.clone();
        spec.scenario = ScenarioRef::Inline(self.base.clone());
        spec.name = Some(self.name.clone());
        toml::to_string(&spec).unwrap_or_default()
    }

    /// Runs in all.
    pub fn total(&self) -> u64 {
        (self.combos.len() * self.seeds.len()) as u64
    }

    /// (combination, seed) of run `id`.
    pub fn locate(&self, id: u64) -> Result<(usize, u64)> {
        if id >= self.total() {
            return Err(SweepError::NoSuchRun {
                id,
                total: self.total(),
            });
        }
        let s = self.seeds.len() as u64;
        Ok(((id / s) as usize, self.seeds[(id % s) as usize]))
    }

    /// `key = value, ...` of a combination (for errors and summaries).
    pub fn describe(&self, combo: usize) -> String {
        self.axes
            .iter()
            .zip(&self.combos[combo])
            .map(|(a, v)| format!("{} = {}", a.name, v))
            .collect::<Vec<_>>()
            .join(", ")
    }

    /// The checked scenario of run `id`.
    pub fn scenario(&self, id: u64) -> Result<Scenario> {
        self.build(id, true)
    }

    fn build(&self, id: u64, check_metrics: bool) -> Result<Scenario> {
        let (combo, seed) = self.locate(id)?;
        let mut table = self.base.clone();
        for (i, (axis, value)) in self.axes.iter().zip(&self.combos[combo]).enumerate() {
            for key in &axis.keys {
                let mut value = value.clone();
                // An integral float into an integer key (a count from a range) becomes an integer.
                if let (Some(toml::Value::Integer(_)), toml::Value::Float(f)) =
                    (key.get(&table), &value)
                    && f.fract() == 0.0
                    && f.abs() < 9.0e15
                {
                    value = toml::Value::Integer(*f as i64);
                }
                key.set(&mut table, value.clone())
                    .map_err(|reason| SweepError::Axis {
                        file: self.file.clone(),
                        setting: SweepError::setting(i, &axis.name, &key.to_string(), &value),
                        combo,
                        reason,
                    })?;
            }
        }
        table.insert("seed".into(), toml::Value::Integer(seed as i64));
        if let Some(d) = self.spec.duration {
            table.insert("duration".into(), toml::Value::Float(d as f64));
        }
        let text = toml::to_string(&table)
            .map_err(|e| SweepError::invalid("scenario", "(table)", e.to_string()))?;
        let this = || crate::explain::Combination {
            file: &self.file,
            axes: &self.axes,
            index: combo,
            values: &self.combos[combo],
            described: self.describe(combo),
            seed,
        };
        let scenario = Scenario::from_toml_str(&text, self.scenario_dir.clone())
            .map_err(|e| crate::explain::combination_error(&this(), &table, e))?;
        if check_metrics {
            self.metrics.check_scenario(&scenario).map_err(|m| {
                let source = SimError::invalid("metrics", self.describe(combo), m);
                crate::explain::combination_error(&this(), &table, source)
            })?;
        }
        Ok(scenario)
    }

    /// Every run's scenario, checked before anything runs: the first failing run (lowest id) names
    /// its combination.
    pub fn check_all(&self) -> Result<Vec<Scenario>> {
        let all: Vec<Result<Scenario>> = (0..self.total())
            .into_par_iter()
            .map(|id| self.scenario(id))
            .collect();
        all.into_iter().collect()
    }
}

/// Two axes setting one key (or one a key inside the other's) would each overwrite the other, and one
/// column would record values that were never run.
fn check_distinct_keys(axes: &[Axis]) -> Result<()> {
    let overlap = |a: &str, b: &str| {
        let under = |x: &str, y: &str| {
            x.strip_prefix(y)
                .is_some_and(|r| r.starts_with('.') || r.starts_with('['))
        };
        a == b || under(a, b) || under(b, a)
    };
    let named = |i: usize| match &axes[i].name {
        n if *n == axes[i].keys[0].to_string() => format!("axes[{i}]"),
        n => format!("axes[{i}] ({n})"),
    };
    for (i, a) in axes.iter().enumerate() {
        for (k, key) in a.keys.iter().enumerate() {
            let key = key.to_string();
            let at = if a.keys.len() == 1 {
                format!("axes[{i}].key")
            } else {
                format!("axes[{i}].keys[{k}]")
            };
            for (j, b) in axes[..=i].iter().enumerate() {
                let before = if j == i { &b.keys[..k] } else { &b.keys[..] };
                if let Some(other) = before.iter().find(|o| overlap(&key, &o.to_string())) {
                    let whom = if j == i {
                        "the same axis".to_string()
                    } else {
                        named(j)
                    };
                    return Err(SweepError::invalid(
                        at,
                        format!("\"{key}\""),
                        format!(
                            "{} and {whom} both set `{other}`: one would overwrite the other, and a column \
                             would record values never run; sweep it on one axis",
                            named(i)
                        ),
                    ));
                }
            }
        }
    }
    Ok(())
}

fn combinations(spec: &SweepSpec, axes: &[Axis]) -> Result<Vec<Vec<toml::Value>>> {
    let samples = |key: &str| {
        spec.samples.filter(|&n| n > 0).ok_or_else(|| {
            SweepError::invalid(
                "samples",
                spec.samples.map_or("(missing)".into(), |n| n.to_string()),
                format!("{key} sampling needs the number of points, > 0"),
            )
        })
    };
    let mut rng = rng::stream(spec.sampling_seed, u64::MAX, 0);
    Ok(match spec.sampling {
        Sampling::Grid => {
            if spec.samples.is_some() {
                return Err(SweepError::invalid(
                    "samples",
                    spec.samples.unwrap_or(0),
                    "only for latin_hypercube and random sampling",
                ));
            }
            let mut combos: Vec<Vec<toml::Value>> = vec![Vec::new()];
            for (i, axis) in axes.iter().enumerate() {
                let mut axis_rng = rng::stream(spec.sampling_seed, i as u64, 0);
                let values = axis.grid_values(i, &mut axis_rng)?;
                combos = combos
                    .into_iter()
                    .flat_map(|c| {
                        values.iter().map(move |v| {
                            let mut c = c.clone();
                            c.push(v.clone());
                            c
                        })
                    })
                    .collect();
                if combos.len() > 10_000_000 {
                    return Err(SweepError::invalid(
                        "axes",
                        combos.len(),
                        "more than 10,000,000 combinations",
                    ));
                }
            }
            combos
        }
        Sampling::LatinHypercube => {
            let n = samples("latin_hypercube")?;
            // One stratum per point along every axis, strata shuffled independently per axis.
            let columns: Vec<Vec<toml::Value>> = axes
                .iter()
                .map(|axis| {
                    let mut perm: Vec<usize> = (0..n).collect();
                    for k in (1..n).rev() {
                        let j = (unit(&mut rng) * (k + 1) as f64) as usize;
                        perm.swap(k, j.min(k));
                    }
                    perm.iter()
                        .map(|&s| axis.at_quantile((s as f64 + unit(&mut rng)) / n as f64))
                        .collect()
                })
                .collect();
            (0..n)
                .map(|k| columns.iter().map(|c| c[k].clone()).collect())
                .collect()
        }
        Sampling::Random => {
            let n = samples("random")?;
            (0..n)
                .map(|_| axes.iter().map(|a| a.at_quantile(unit(&mut rng))).collect())
                .collect()
        }
    })
}

/// FNV-1a over byte strings (a stable hash: the same sweep gives the same fingerprint everywhere).
fn fnv1a(parts: &[&[u8]]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for part in parts {
        for b in part.iter().chain(&[0xff]) {
            h ^= *b as u64;
            h = h.wrapping_mul(0x0000_0100_0000_01b3);
        }
    }
    h
}
