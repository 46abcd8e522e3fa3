//! The `colcos` command line's arguments: the binary dispatches on them, and the command-line fuzz
//! target (fuzz/) parses with this very definition.
use clap::{Parser, Subcommand};
use std::path::PathBuf;

// (No doc comment on the types: clap would take it for the long help.)
#[derive(Parser)]
#[command(
    name = "colcos",
    version,
    about = "Multi-pheromone swarm robotics simulator (ColCOSPhi)"
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Subcommand)]
pub enum Command {
    /// Run a scenario: writes trajectory.csv, screen.png, run.gif, fields/*.npy and summary.json.
    Run(crate::cmd::run::RunArgs),
    /// Show a scenario's screen image in a window (full screen on a chosen monitor, or windowed), or
    /// render it headless to PNG.
    Display(crate::cmd::display::DisplayArgs),
    /// Reproduce the paper's case studies (all trials in parallel): figures, CSVs, summary.json/.md.
    Experiment(crate::cmd::experiment::ExperimentArgs),
    /// Drive real robots with a scenario's behaviours: poses from the tracker, pheromone injected and
    /// the field stepped by the simulator, commands over the radio link, safety stops by a watchdog.
    Bridge(crate::cmd::bridge::BridgeArgs),
    /// The digital twin: the simulator serving the rig's wire formats (SwarmCon over TCP, the robots'
    /// serial protocol over a pseudo-terminal or UDP) for `colcos bridge` to drive.
    Twin(crate::cmd::twin::TwinArgs),
    /// Calibrate the rig over its own wires (screen <-> camera, latency, colour sensors); each writes
    /// a file the scenario's `[rig]` section names.
    Calibrate(crate::cmd::calibrate::CalibrateArgs),
    /// Put a rig log (`rig.mcap`) through the live loop again and check that the same inputs give
    /// the same command bytes.
    Replay(crate::cmd::replay::ReplayArgs),
    /// The rig's pre-flight: `colcos rig check SCENARIO` runs the behaviours on a digital twin first.
    Rig {
        #[command(subcommand)]
        command: crate::cmd::rig::RigCommand,
    },
    /// Run a batch of scenarios over axes of parameters and seeds (a sweep file), in parallel and
    /// resumable: results.csv, plots/ and summary.md (docs/sweeps.md).
    Sweep(crate::cmd::sweep::SweepArgs),
    /// Check a scenario file and print what it sets up, without running it.
    Check { scenario: PathBuf },
    /// List the behaviours a scenario can name.
    Behaviours,
}
