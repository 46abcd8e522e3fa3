//! How to build an environment: task, scenario, episode length, action kind, extras.
use crate::error::{EnvError, Result};
use colcos_sim::scenario::Scenario;
use std::path::PathBuf;

/// Where the scenario comes from.
#[derive(Clone, Debug, Default)]
pub enum ScenarioSource {
    /// The task's built-in default scenario.
    #[default]
    Default,
    /// A scenario file (TOML) on disk.
    File(PathBuf),
    /// Scenario text (TOML); relative paths resolve against the current directory.
    Text(String),
}

impl ScenarioSource {
    /// Loads and validates the scenario; `default_text` is the task's own.
    pub fn load(&self, default_text: &str) -> Result<Scenario> {
        Ok(match self {
            ScenarioSource::Default => Scenario::from_toml_str(default_text, ".")?,
            ScenarioSource::File(path) => Scenario::from_file(path)?,
            ScenarioSource::Text(text) => Scenario::from_toml_str(text, ".")?,
        })
    }
}

/// The action space of every agent.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ActionKind {
    /// Two wheel speeds in `[-1, 1]`, as fractions of the robot's largest wheel speed.
    #[default]
    Continuous,
    /// One of [`crate::encoding::DISCRETE_ACTIONS`].
    Discrete,
}

impl std::str::FromStr for ActionKind {
    type Err = EnvError;
    fn from_str(s: &str) -> Result<Self> {
        match s {
            "continuous" => Ok(ActionKind::Continuous),
            "discrete" => Ok(ActionKind::Discrete),
            _ => Err(EnvError::param(
                "action",
                format!("{s:?} is not \"continuous\" or \"discrete\""),
            )),
        }
    }
}

/// What happens when every agent of a world is done, as in Gymnasium 1.x vector environments.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum AutoresetMode {
    /// The next `step` resets the world and ignores its actions (Gymnasium's default).
    #[default]
    NextStep,
    /// The world is reset within the same `step`; the final observation goes to `final_obs`.
    SameStep,
    /// Never: the caller resets done worlds with `reset(mask)`; stepping a done world is an error.
    Disabled,
}

impl std::str::FromStr for AutoresetMode {
    type Err = EnvError;
    fn from_str(s: &str) -> Result<Self> {
        match s.to_ascii_lowercase().as_str() {
            "next_step" | "nextstep" => Ok(AutoresetMode::NextStep),
            "same_step" | "samestep" => Ok(AutoresetMode::SameStep),
            "disabled" => Ok(AutoresetMode::Disabled),
            _ => Err(EnvError::param(
                "autoreset_mode",
                format!("{s:?} is not \"next_step\", \"same_step\" or \"disabled\""),
            )),
        }
    }
}

/// The egocentric screen patch: a `pixels x pixels` RGB image of the screen under and ahead of a robot.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PatchConfig {
    /// Side of the image, pixels.
    pub pixels: usize,
    /// Side of the square of screen it shows, m.
    pub side: f32,
}

impl Default for PatchConfig {
    /// 16 x 16 pixels over 8 cm (2 robot diameters).
    fn default() -> Self {
        PatchConfig {
            pixels: 16,
            side: 0.08,
        }
    }
}

/// A whole environment configuration.
#[derive(Clone, Debug)]
pub struct EnvConfig {
    /// Task name from [`crate::task::registry`].
    pub task: String,
    pub scenario: ScenarioSource,
    /// Task parameters (JSON object); unknown keys are refused by the task.
    pub params: serde_json::Value,
    /// Steps per episode before truncation (0: the scenario's duration).
    pub max_cycles: u64,
    pub action: ActionKind,
    pub autoreset: AutoresetMode,
    /// Also compute the global state (all robot poses) for centralised critics.
    pub global_state: bool,
    pub patch: Option<PatchConfig>,
    pub num_envs: usize,
    /// Worker threads (None: rayon's default, one per core).
    pub num_threads: Option<usize>,
    /// Seed used until `reset` is given another.
    pub seed: u64,
    /// Field backend of the grid pheromones; `None`: the scenario's `[field] backend`.
    pub backend: Option<colcos_sim::field::BackendChoice>,
    /// The worlds' contact solver; `None`: the scenario's `physics` (rapier unless it says `discs`).
    pub physics: Option<colcos_sim::robot::PhysicsBackend>,
    /// Pass the agents' commands through the safety shield (`[rig] shield` of the scenario), as every
    /// plant does on the rig, so that training sees what deployment does.
    pub shield: bool,
}

impl EnvConfig {
    pub fn new(task: impl Into<String>) -> Self {
        EnvConfig {
            task: task.into(),
            scenario: ScenarioSource::Default,
            params: serde_json::Value::Object(Default::default()),
            max_cycles: 0,
            action: ActionKind::Continuous,
            autoreset: AutoresetMode::NextStep,
            global_state: true,
            patch: None,
            num_envs: 1,
            num_threads: None,
            seed: 0,
            backend: None,
            physics: None,
            shield: true,
        }
    }
}
