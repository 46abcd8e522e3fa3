//! `colcos run`: the run library of `colcos-sim` ([`colcos_sim::run`]) with this crate's field backend
//! choice (GPU when built with the `gpu` feature) and a progress bar on the terminal.
use anyhow::Result;
use colcos_sim::prelude::*;
use std::path::Path;

pub use colcos_sim::run::RunReport;

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
    let bar = if opts.progress {
        progress_bar(scenario.steps())
    } else {
        indicatif::ProgressBar::hidden()
    };
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

fn progress_bar(steps: u64) -> indicatif::ProgressBar {
    let bar = indicatif::ProgressBar::new(steps);
    bar.set_style(
        indicatif::ProgressStyle::with_template("{spinner} [{elapsed_precise}] {bar:40.cyan/blue} {pos}/{len} steps ({per_sec}, eta {eta})")
            .expect("static template")
            .progress_chars("=> "),
    );
    bar
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
