//! colcos: a simulator, RL environment and hardware bridge for multi-pheromone swarm robotics, after
//! the ColCOSPhi system. This facade re-exports the library crates; the `colcos` binary is the CLI.

pub use colcos_bridge as bridge;
pub use colcos_sim as sim;

pub mod backend;
pub mod calibrate;
pub mod cli;
pub mod display;
pub mod experiment;
pub mod identify;
pub mod preflight;
pub mod replay;
pub mod report;
pub mod rig;
pub mod run;
pub mod scenario_write;
pub mod sweep;
