//! The subcommands of the `colcos` command line, a module each, named after it (`colcos rig excite`
//! and `colcos rig identify` are [`identify`]), and the dispatch of parsed arguments
//! ([`crate::cli`]) to them.
use crate::cli::Command;
use anyhow::{Context, Result};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

pub mod behaviours;
pub mod bridge;
pub mod calibrate;
pub mod check;
pub mod display;
pub mod experiment;
pub mod identify;
pub mod replay;
pub mod rig;
pub mod run;
pub mod sweep;
pub mod twin;

// `--threads` of `colcos run` and `colcos sweep`, flattened into their arguments. (No doc comment:
// clap would take it for the long help.)
#[derive(clap::Args, Clone, Debug)]
pub struct ThreadsArg {
    /// Worker threads, 1 to 1024 (default: all cores). Results do not depend on it.
    // 0 would silently mean "all cores"; beyond 1024 each thread's stack only costs memory.
    #[arg(long, value_parser = clap::builder::RangedU64ValueParser::<usize>::new().range(1..=1024))]
    pub threads: Option<usize>,
}

/// Runs `command`; what it has to say when done goes into `text` (also when it fails part way).
pub fn run_command(command: Command, text: &mut String) -> Result<()> {
    match command {
        Command::Run(args) => run::main(args, text),
        Command::Display(args) => display::main(args),
        Command::Experiment(args) => experiment::main(args),
        Command::Sweep(args) => sweep::main(args),
        Command::Bridge(args) => bridge::bridge(args, text),
        Command::Twin(args) => twin::twin(args, text),
        Command::Calibrate(args) => calibrate::main(args, text),
        Command::Replay(args) => replay::run(args, text),
        Command::Rig { command } => rig::run(command, text),
        Command::Check { scenario } => check::main(&scenario, text),
        Command::Behaviours => behaviours::main(text),
    }
}

/// A flag that Ctrl-C and SIGTERM set: a long command ends at the next point where it can stop with
/// its outputs whole.
fn stop_on_signal() -> Result<Arc<AtomicBool>> {
    let stop = Arc::new(AtomicBool::new(false));
    let s = stop.clone();
    ctrlc::set_handler(move || s.store(true, Ordering::Relaxed))
        .context("installing the Ctrl-C / SIGTERM handler")?;
    Ok(stop)
}

/// Sizes rayon's global pool to `threads` workers (all cores when `None`): `--threads`.
fn use_threads(threads: Option<usize>) -> Result<()> {
    if let Some(n) = threads {
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build_global()
            .context("setting up the thread pool")?;
    }
    Ok(())
}

/// A progress bar on the terminal over `len` `unit`s (steps, trials), or a hidden one unless `show`.
fn progress_bar(len: u64, unit: &str, show: bool) -> indicatif::ProgressBar {
    if !show {
        return indicatif::ProgressBar::hidden();
    }
    let bar = indicatif::ProgressBar::new(len);
    let template = format!(
        "{{spinner}} [{{elapsed_precise}}] {{bar:40.cyan/blue}} {{pos}}/{{len}} {unit} ({{per_sec}}, eta {{eta}})"
    );
    bar.set_style(
        indicatif::ProgressStyle::with_template(&template)
            .expect("a valid template")
            .progress_chars("=> "),
    );
    bar
}
