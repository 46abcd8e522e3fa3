//! What a plant is asked for ([`PlantKind`], [`PlantOptions`]) and what can go wrong ([`PlantError`]).
use crate::TwinScenario;
use colcos_bridge::rig::replay;
use colcos_env::EnvError;
use std::path::PathBuf;

/// Where a plant's arena is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PlantKind {
    Twin,
    Rig,
    Replay,
}

impl std::str::FromStr for PlantKind {
    type Err = PlantError;
    fn from_str(s: &str) -> Result<Self, PlantError> {
        match s {
            "twin" => Ok(PlantKind::Twin),
            "rig" => Ok(PlantKind::Rig),
            "replay" => Ok(PlantKind::Replay),
            _ => Err(PlantError::option(
                "plant",
                format!("{s:?} is not \"sim\", \"twin\", \"rig\" or \"replay\""),
            )),
        }
    }
}

/// How to reach a plant.
#[derive(Clone, Debug)]
pub struct PlantOptions {
    pub kind: PlantKind,
    /// The tracker's URL (`swarmcon://HOST:PORT`, `udp://...`); a twin without one starts in-process.
    pub tracker: Option<String>,
    /// The robots' link URL (`serial://...`, `udp://...`).
    pub robots: Option<String>,
    /// `replay`: the rig log to replay. `twin`, `rig`: where to write the rig log (none: no log).
    pub log: Option<PathBuf>,
    /// `reset` drives the robots to the episode's start poses (twin, rig).
    pub goto: bool,
    /// Longest a reset's go-to may take, s.
    pub goto_timeout: f64,
    /// `rig`: how fresh and precise the screen calibration must be.
    pub calibration: CalibrationLimits,
    /// `twin` started here: the scenario the twin plays (its true tracker latency, sensors, robot
    /// body) where it differs from the host's; None: the host's own.
    pub twin_scenario: Option<TwinScenario>,
    /// `twin` started here: the twin's robots' hidden true values, a file of `[[robot]]` entries
    /// (`colcos twin --truth`) over the twin's scenario; the host keeps its nominal ones.
    pub twin_truth: Option<PathBuf>,
}

impl PlantOptions {
    pub fn new(kind: PlantKind) -> PlantOptions {
        PlantOptions {
            kind,
            tracker: None,
            robots: None,
            log: None,
            goto: true,
            goto_timeout: 30.0,
            calibration: CalibrationLimits::default(),
            twin_scenario: None,
            twin_truth: None,
        }
    }
}

/// What the rig plant asks of its screen calibration before it drives real robots.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CalibrationLimits {
    /// Oldest it may be, s.
    pub max_age: f64,
    /// Largest RMS reprojection error, mm.
    pub max_error_mm: f64,
}

impl Default for CalibrationLimits {
    /// A week, 3 mm.
    fn default() -> Self {
        CalibrationLimits {
            max_age: 7.0 * 86400.0,
            max_error_mm: 3.0,
        }
    }
}

#[derive(Debug, thiserror::Error)]
pub enum PlantError {
    #[error(transparent)]
    Env(#[from] EnvError),
    #[error(transparent)]
    Sim(#[from] colcos_sim::error::SimError),
    #[error("tracker: {0}")]
    Source(#[from] colcos_bridge::SourceError),
    #[error("robot link: {0}")]
    Link(#[from] colcos_bridge::LinkError),
    #[error(transparent)]
    Replay(#[from] replay::ReplayError),
    #[error("{0}")]
    Io(String),
    #[error("`{key}`: {reason}")]
    Option { key: String, reason: String },
    #[error("{0}")]
    State(String),
    /// The tracker or the robot link cannot be reached: the URL and the reason.
    #[error("{0}")]
    Unreachable(String),
}

impl PlantError {
    pub(super) fn option(key: &str, reason: impl Into<String>) -> PlantError {
        PlantError::Option {
            key: key.into(),
            reason: reason.into(),
        }
    }
}
