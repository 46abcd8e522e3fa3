//! Tasks by name.
use super::{Task, aggregation, alarm, colony, coverage, external, foraging, trail};
use crate::config::ScenarioSource;
use crate::error::{EnvError, Result};
use colcos_sim::scenario::Scenario;

type Builder = fn(&Scenario, &serde_json::Value) -> Result<Box<dyn Task>>;

/// Every task: name, description, default scenario (TOML), builder.
const REGISTRY: &[(&str, &str, &str, Builder)] = &[
    (
        "aggregation",
        aggregation::DESCRIPTION,
        aggregation::DEFAULT_SCENARIO,
        aggregation::build,
    ),
    (
        "foraging",
        foraging::DESCRIPTION,
        foraging::DEFAULT_SCENARIO,
        foraging::build,
    ),
    (
        "trail",
        trail::DESCRIPTION,
        trail::DEFAULT_SCENARIO,
        trail::build,
    ),
    (
        "colony",
        colony::DESCRIPTION,
        colony::DEFAULT_SCENARIO,
        colony::build,
    ),
    (
        "coverage",
        coverage::DESCRIPTION,
        coverage::DEFAULT_SCENARIO,
        coverage::build,
    ),
    (
        "alarm",
        alarm::DESCRIPTION,
        alarm::DEFAULT_SCENARIO,
        alarm::build,
    ),
    // Last, and left out of `list`: built for a `colcos.Task` written in Python, on the scenario it
    // names (the `trail` task's by default).
    (
        external::NAME,
        external::DESCRIPTION,
        trail::DEFAULT_SCENARIO,
        external::build,
    ),
];

/// Names and one-line descriptions of all tasks.
pub fn list() -> impl Iterator<Item = (&'static str, &'static str)> {
    (REGISTRY.iter())
        .filter(|(n, ..)| *n != external::NAME)
        .map(|(n, d, _, _)| (*n, *d))
}

/// The built-in scenario text of task `name`.
pub fn default_scenario(name: &str) -> Result<&'static str> {
    find(name).map(|(_, _, s, _)| *s)
}

/// Builds task `name` over the scenario from `source`, with `params` (a JSON object).
pub fn build(
    name: &str,
    source: &ScenarioSource,
    params: &serde_json::Value,
) -> Result<(Box<dyn Task>, Scenario)> {
    let (_, _, default, builder) = find(name)?;
    // A task option may pick another built-in scenario (`trail`'s `maze`).
    let default = if name == "trail" {
        trail::default_scenario(params)
    } else {
        default
    };
    let scenario = source.load(default)?;
    let task = builder(&scenario, params)?;
    if task.agents().is_empty() {
        return Err(EnvError::param(name, "the scenario has no agent robots"));
    }
    Ok((task, scenario))
}

fn find(name: &str) -> Result<&'static (&'static str, &'static str, &'static str, Builder)> {
    REGISTRY
        .iter()
        .find(|(n, _, _, _)| *n == name)
        .ok_or_else(|| EnvError::UnknownTask {
            name: name.to_string(),
            known: list().map(|(n, _)| n).collect::<Vec<_>>().join(", "),
        })
}
