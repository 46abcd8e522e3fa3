//! Scenario files: TOML parsed into a [`ScenarioSpec`] (unknown keys rejected, errors with the key path),
//! then validated before anything runs; or built in code with [`ScenarioBuilder`].

mod builder;
pub mod individual;
mod limits;
pub(crate) mod placement;
mod randomize;
mod rig;
mod spec;
mod validate;

pub use builder::ScenarioBuilder;
pub use individual::{Individual, IndividualFile, IndividualSpec, RobotIndividual};
pub use limits::{
    MAX_CELLS, MAX_DEPOSIT_CELLS, MAX_GIF_SIDE, MAX_IMAGE_PIXELS, MAX_MAP_CELL_VISITS,
    MAX_POLYLINE_POINTS, MAX_POSES_IN_FLIGHT, MAX_ROBOTS, MAX_SOURCE_PAIRS, MAX_SUBSTEPS,
    MAX_TRACKER_LATENCY, MAX_TRACKER_RATE_HZ,
};
pub use randomize::{RandomizeSpec, Randomized};
pub use rig::{BROADCAST_ID, Firmware, RigSpec, SensorSource};
pub use spec::*;

use crate::error::{Result, SimError};
use std::path::{Path, PathBuf};

/// A checked scenario, ready to build a [`crate::world::World`].
#[derive(Clone, Debug)]
pub struct Scenario {
    pub spec: ScenarioSpec,
    /// Directory that relative paths in the file (images) are resolved against.
    pub base_dir: PathBuf,
}

impl Scenario {
    /// This scenario with its robots' values taken from the file `truth` alone (`colcos twin
    /// --truth`): a twin's hidden per-robot truths, where the host drives with the scenario's nominal
    /// values. The file is read and checked here, so that a bad one is refused before anything starts.
    pub fn with_truth(&self, truth: &Path) -> Result<Scenario> {
        let shown = truth.display().to_string();
        let loaded = individual::IndividualFile::load(truth)
            .map_err(|e| SimError::invalid("truth", format!("{shown:?}"), e.to_string()))?;
        individual::validate_entries(&loaded.robot, "robot", self.robot_count())
            .map_err(|e| SimError::invalid("truth", format!("{shown:?}"), individual::inner(e)))?;
        let absolute = std::path::absolute(truth).unwrap_or_else(|_| truth.to_path_buf());
        let mut out = self.clone();
        out.spec.individual = individual::IndividualSpec {
            file: Some(absolute.to_string_lossy().into_owned()),
            robot: Vec::new(),
        };
        validate::validate(&out)?;
        Ok(out)
    }

    /// Its obstacles (none when it lists none), built as the world builds them.
    pub fn obstacles(&self) -> Result<crate::arena::Obstacles> {
        crate::arena::Obstacles::build_in(
            &self.spec.obstacles,
            self.spec.arena.shape.as_ref(),
            self.arena_size(),
            &self.base_dir,
        )
    }

    /// Reads, parses and validates a scenario file.
    pub fn from_file(path: impl AsRef<Path>) -> Result<Self> {
        let path = path.as_ref();
        let text = std::fs::read_to_string(path)
            .map_err(|e| SimError::io(format!("reading scenario {}", path.display()), e))?;
        let base = path.parent().map(Path::to_path_buf).unwrap_or_default();
        Self::from_toml_str(&text, base).map_err(|e| match e {
            SimError::Parse { message, .. } => SimError::Parse {
                path: path.display().to_string(),
                message,
            },
            other => other,
        })
    }

    /// Parses and validates scenario text; `base_dir` resolves relative paths.
    pub fn from_toml_str(text: &str, base_dir: impl Into<PathBuf>) -> Result<Self> {
        let spec = parse_spec(text)?;
        Self::from_spec(spec, base_dir)
    }

    /// Validates an already parsed spec.
    pub fn from_spec(spec: ScenarioSpec, base_dir: impl Into<PathBuf>) -> Result<Self> {
        let scenario = Scenario {
            spec,
            base_dir: base_dir.into(),
        };
        validate::validate(&scenario)?;
        Ok(scenario)
    }

    /// Arena size, m.
    pub fn arena_size(&self) -> glam::Vec2 {
        let s = self.spec.arena.size.unwrap_or(self.spec.screen.size);
        glam::Vec2::new(s[0], s[1])
    }

    /// Number of ticks in a run.
    pub fn steps(&self) -> u64 {
        (self.spec.duration / self.spec.dt).round() as u64
    }

    /// Total number of robots.
    pub fn robot_count(&self) -> usize {
        // Saturating: validation reads it before it has bounded the counts.
        self.spec
            .robots
            .iter()
            .fold(0usize, |n, g| n.saturating_add(g.count))
    }

    /// The pheromones' names, in the scenario's order.
    pub fn pheromone_names(&self) -> impl Iterator<Item = &str> {
        self.spec.pheromones.iter().map(|p| p.name.as_str())
    }

    /// Index of the pheromone called `name`.
    pub fn pheromone_index(&self, name: &str) -> Option<usize> {
        self.spec.pheromones.iter().position(|p| p.name == name)
    }

    /// Replaces the seed and/or duration and checks the result again.
    pub fn with_overrides(mut self, seed: Option<u64>, duration: Option<f32>) -> Result<Self> {
        if let Some(s) = seed {
            self.spec.seed = s;
        }
        if let Some(d) = duration {
            self.spec.duration = d;
        }
        validate::validate(&self)?;
        Ok(self)
    }

    /// The scenario as TOML (what a run actually used).
    pub fn to_toml(&self) -> String {
        toml::to_string_pretty(&self.spec).unwrap_or_default()
    }

    /// The scenario as TOML with its file paths (image maps, rig calibrations) made absolute, so that
    /// the copy a run saves in its output directory runs again from there.
    pub fn to_toml_standalone(&self) -> String {
        let mut spec = self.spec.clone();
        let absolute = |p: &mut String| {
            let joined = self.base_dir.join(&*p);
            if let Ok(abs) = std::path::absolute(&joined) {
                *p = abs.to_string_lossy().into_owned();
            }
        };
        spec.pheromones
            .iter_mut()
            .flat_map(|ph| ph.maps.iter_mut())
            .filter_map(|m| match m {
                MapSpec::Image { image, .. } => Some(image),
                MapSpec::Polyline { .. } => None,
            })
            .for_each(absolute);
        spec.obstacles
            .iter_mut()
            .filter_map(|o| o.image.as_mut())
            .for_each(absolute);
        spec.rig.screen_calibration.iter_mut().for_each(absolute);
        spec.rig.colour_calibration.iter_mut().for_each(absolute);
        spec.rig.onboard.iter_mut().for_each(absolute);
        spec.rig.compensate.iter_mut().for_each(absolute);
        spec.individual.file.iter_mut().for_each(absolute);
        toml::to_string_pretty(&spec).unwrap_or_default()
    }
}

/// TOML text to spec. Errors name the key path (`robots[0].count`) and what was wrong.
pub fn parse_spec(text: &str) -> Result<ScenarioSpec> {
    let de = toml::de::Deserializer::parse(text).map_err(|e| SimError::Parse {
        path: "<text>".into(),
        message: e.to_string(),
    })?;
    let spec: ScenarioSpec = serde_path_to_error::deserialize(de).map_err(|e| {
        let path = e.path().to_string();
        let error = e.into_inner();
        // A table checked as a whole (a map) names its key at fault as `.key: ...`.
        let sub = (error.message().strip_prefix('.')).and_then(|r| r.split_once(": "));
        let message = match sub {
            Some((key, reason)) => format!("at `{path}.{key}`: {reason}"),
            None if path == "." || path.is_empty() => error.to_string(),
            None => format!("at `{path}`: {error}"),
        };
        SimError::Parse {
            path: "<text>".into(),
            message,
        }
    })?;
    check_array_lengths(text, &spec)?;
    Ok(spec)
}

/// Serde fills a fixed-size array (`[x, y]`) from the first elements of a longer TOML array and
/// drops the rest, so `resolution = [1920, 1080, 3]` or a 3-D polyline point would pass unnoticed.
/// Every array of the file must therefore come back from the parsed spec with the same length.
fn check_array_lengths(text: &str, spec: &ScenarioSpec) -> Result<()> {
    let (Ok(input), Ok(parsed)) = (text.parse::<toml::Table>(), toml::Table::try_from(spec)) else {
        return Ok(());
    };
    fn walk(path: &str, input: &toml::Value, parsed: &toml::Value) -> Result<()> {
        match (input, parsed) {
            (toml::Value::Array(a), toml::Value::Array(b)) => {
                if a.len() != b.len() {
                    let mut shown = input.to_string();
                    if shown.chars().count() > 80 {
                        shown = format!("{}...", shown.chars().take(77).collect::<String>());
                    }
                    return Err(SimError::invalid(
                        path,
                        shown,
                        format!("expected {} values, got {}", b.len(), a.len()),
                    ));
                }
                for (n, (x, y)) in a.iter().zip(b).enumerate() {
                    walk(&format!("{path}[{n}]"), x, y)?;
                }
                Ok(())
            }
            (toml::Value::Table(a), toml::Value::Table(b)) => walk_tables(path, a, b),
            _ => Ok(()),
        }
    }
    fn walk_tables(path: &str, input: &toml::Table, parsed: &toml::Table) -> Result<()> {
        for (k, v) in input {
            if let Some(w) = parsed.get(k) {
                let key = if path.is_empty() {
                    k.clone()
                } else {
                    format!("{path}.{k}")
                };
                walk(&key, v, w)?;
            }
        }
        Ok(())
    }
    walk_tables("", &input, &parsed)
}
