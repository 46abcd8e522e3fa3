//! colcos: a simulator, RL environment and hardware bridge for multi-pheromone swarm robotics, after
//! the ColCOSPhi system. This facade re-exports the library crates; the `colcos` binary is the CLI.

pub use colcos_bridge as bridge;
pub use colcos_sim as sim;

pub mod backend;
pub mod cli;
pub mod cmd;
pub mod report;
pub mod scenario_write;

// The case studies and the run library, under the names the tests and examples use.
pub use cmd::{experiment, run};
