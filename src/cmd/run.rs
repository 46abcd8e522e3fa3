//! `colcos run`: the run library of `colcos-sim` ([`colcos_sim::run`]) with this crate's field backend
//! choice (GPU when built with the `gpu` feature) and a progress bar on the terminal.
use anyhow::Result;
use clap::Args;
use colcos_sim::prelude::*;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

pub use colcos_sim::run::RunReport;

// (No doc comment: clap would take it for the long help.)
#[derive(Args, Debug)]
pub struct RunArgs {
    /// Scenario file (TOML).
    scenario: PathBuf,
    /// Output directory [default: runs/<scenario file name without .toml>].
    #[arg(long)]
    out: Option<PathBuf>,
    /// Override the scenario's seed.
    #[arg(long)]
    seed: Option<u64>,
    /// Override the scenario's duration, s.
    #[arg(long)]
    duration: Option<f32>,
    #[command(flatten)]
    pool: super::ThreadsArg,
    /// No progress bar.
    #[arg(long)]
    quiet: bool,
    /// Field backend: cpu, gpu or auto (overrides the scenario's `field.backend`).
    #[arg(long)]
    backend: Option<colcos_sim::field::BackendChoice>,
}

/// `colcos run`: the scenario run to its end (or to Ctrl-C / SIGTERM), what it wrote listed in `text`.
pub fn main(args: RunArgs, text: &mut String) -> Result<()> {
    super::use_threads(args.pool.threads)?;
    let mut sc = Scenario::from_file(&args.scenario)?.with_overrides(args.seed, args.duration)?;
    if let Some(b) = args.backend {
        sc.spec.field.backend = b;
    }
    let out = args.out.unwrap_or_else(|| {
        PathBuf::from("runs").join(args.scenario.file_stem().unwrap_or_default())
    });
    // Ctrl-C and SIGTERM end the run after the current step, with every output written.
    let stop = super::stop_on_signal()?;
    let report = run(
        &sc,
        &out,
        &RunOptions {
            progress: !args.quiet,
            no_gif: false,
            stop: Some(stop),
        },
    )?;
    if report.interrupted {
        writeln!(
            text,
            "interrupted after {} of {} steps: the outputs hold what ran",
            report.steps,
            sc.steps()
        )?;
    }
    writeln!(text, "field backend: {}", report.backend)?;
    writeln!(
        text,
        "{} robots, {} steps ({:.2} s simulated) in {:.2} s: {:.1}x real time",
        report.robots,
        report.steps,
        report.sim_seconds,
        // The whole run (world build, log, GIF, files): what the user waited for.
        report.total_wall_seconds,
        report.overall_real_time_factor()
    )?;
    for f in &report.files {
        writeln!(text, "  wrote {}", f.display())?;
    }
    Ok(())
}

/// Options of one run beyond the scenario.
#[derive(Debug, Clone, Default)]
pub struct RunOptions {
    /// Draw a progress bar on the terminal.
    pub progress: bool,
    /// Skip the GIF (tests that compare logs do not need it).
    pub no_gif: bool,
    /// Set to end the run after the current step, writing the outputs of what ran (the CLI sets it on
    /// Ctrl-C and SIGTERM).
    pub stop: Option<std::sync::Arc<std::sync::atomic::AtomicBool>>,
}

/// Runs `scenario` to its end, writing into `out_dir`, with the backend the scenario's `field.backend`
/// asks for.
pub fn run(scenario: &Scenario, out_dir: &Path, opts: &RunOptions) -> Result<RunReport> {
    let choice = scenario.spec.field.backend;
    let bar = super::progress_bar(scenario.steps(), "steps", opts.progress);
    let mut on_step = |done: u64, total: u64| {
        bar.set_position(done);
        if done == total {
            bar.finish_and_clear();
        }
    };
    let report = colcos_sim::run::run(
        scenario,
        out_dir,
        colcos_sim::run::RunOptions {
            no_gif: opts.no_gif,
            backend: Some(Box::new(move |world: &mut World| {
                crate::backend::try_install(world, choice).map_err(Into::into)
            })),
            on_step: Some(&mut on_step),
            stop: opts.stop.as_deref(),
        },
    );
    bar.finish_and_clear();
    // The run error's message already ends with its cause: as an anyhow chain the CLI's `{:#}` would
    // print the cause twice.
    report.map_err(|e| anyhow::anyhow!("{e}"))
}

/// Gives libwayland an empty private runtime directory when `XDG_RUNTIME_DIR` is unset or not an
/// absolute path. GPU drivers' EGL probes for a Wayland compositor on every GPU run, and libwayland
/// then prints "XDG_RUNTIME_DIR is invalid or not set in the environment" (ssh sessions, containers)
/// although no window is wanted; in an empty directory the probe finds no socket and stays silent.
/// A valid value (set by the user's login) is kept. Call it first in `main`, before any thread starts: it sets an
/// environment variable.
pub fn quiet_wayland_probe() {
    let valid = std::env::var_os("XDG_RUNTIME_DIR")
        .is_some_and(|v| Path::new(&v).is_absolute() && Path::new(&v).is_dir());
    if valid {
        return;
    }
    let user = std::env::var("USER").unwrap_or_default();
    let dir = std::env::temp_dir().join(format!("colcos-runtime-{user}"));
    let mut builder = std::fs::DirBuilder::new();
    builder.recursive(true);
    #[cfg(unix)]
    std::os::unix::fs::DirBuilderExt::mode(&mut builder, 0o700);
    if builder.create(&dir).is_ok() && dir.is_absolute() {
        // SAFETY: called at the start of `main`, before any other thread exists.
        unsafe { std::env::set_var("XDG_RUNTIME_DIR", &dir) };
    }
}
