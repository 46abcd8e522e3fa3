//! Plants for the RL environments: the same task, spaces, outputs and safety shield as one world of the
//! simulated batch (`colcos_env::VecEnv`), with the arena a real rig, the digital twin, or a recorded
//! rig run. A policy written against one runs unchanged on the others.
//!
//! - `twin`: the digital twin over loopback (started in this process when no addresses are given);
//! - `rig`: the lab's tracker and robots, by URL;
//! - `replay`: a rig log (`rig.mcap`) fed tick by tick: the recorded poses, telemetry and tick times,
//!   with the policy's commands in place of the recorded behaviours' (nothing moves in response).
//!
//! `step` is paced to the screen's 20 ms on the twin and the rig; `reset` drives the robots to the
//! episode's start poses with a tracker-guided [`GoTo`], bounded in time, unless asked not to.
//!
//! [`preflight`] runs a scenario's behaviours on a twin started here and refuses what should not drive
//! a rig. This crate joins the RL environment (`colcos-env`) and the bridge (`colcos-bridge`): neither
//! depends on the other.
mod calibration_gate;
mod deferred;
pub(crate) mod driver;
mod goto;
mod live_env;
mod options;
pub mod preflight;
mod twin_scenario;

pub use goto::GoTo;
pub use live_env::{GoToReport, LiveEnv};
pub use options::{CalibrationLimits, PlantError, PlantKind, PlantOptions};
pub use twin_scenario::TwinScenario;
