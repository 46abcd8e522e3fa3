//! The `colcos` command line.
use anyhow::{Context, Result};
use clap::Parser;
use colcos::cli::{Cli, Command};
use colcos::report::print_report;
use colcos::run::{RunOptions, run};
use colcos::sim::prelude::*;
use std::fmt::Write as _;
use std::path::PathBuf;
use std::process::ExitCode;

fn main() -> ExitCode {
    colcos::run::quiet_wayland_probe();
    init_logging();
    match real_main() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {}", error_text(&e));
            ExitCode::FAILURE
        }
    }
}

/// The error and its causes on one line, each cause once: a library error that already ends with its
/// cause (`reading scenario x.toml: No such file ...`) does not get it again.
fn error_text(e: &anyhow::Error) -> String {
    let mut text = e.to_string();
    for cause in e.chain().skip(1) {
        let c = cause.to_string();
        if !text.ends_with(&c) {
            text.push_str(": ");
            text.push_str(&c);
        }
    }
    text
}

/// The libraries report through the `log` crate; their messages reach the terminal (stderr) at info
/// level unless `RUST_LOG` says otherwise. Dependencies such as wgpu stay quiet by default.
fn init_logging() {
    use std::io::Write as _;
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or("colcos=info"))
        .format(|buf, record| match record.level() {
            log::Level::Info => writeln!(buf, "{}", record.args()),
            log::Level::Warn => writeln!(buf, "warning: {}", record.args()),
            level => writeln!(buf, "{}: {}", level.as_str().to_lowercase(), record.args()),
        })
        .init();
}

fn real_main() -> Result<()> {
    let mut out = String::new();
    let result = run_command(Cli::parse().command, &mut out);
    // What a refused or failed command measured before it stopped (pre-flight counts, a bridge's
    // summary) is printed too, then the error.
    print_report(&out)?;
    result
}

fn run_command(command: Command, text: &mut String) -> Result<()> {
    match command {
        Command::Display(args) => colcos::display::main(args),
        Command::Experiment(args) => colcos::experiment::main(args),
        Command::Sweep(args) => colcos::sweep::main(args),
        Command::Bridge(args) => colcos::rig::bridge(args, text),
        Command::Twin(args) => colcos::rig::twin(args, text),
        Command::Calibrate(args) => colcos::calibrate::main(args, text),
        Command::Replay(args) => colcos::replay::run(args, text),
        Command::Rig { command } => colcos::preflight::run(command, text),
        Command::Run {
            scenario,
            out,
            seed,
            duration,
            threads,
            quiet,
            backend,
        } => {
            if let Some(n) = threads {
                rayon::ThreadPoolBuilder::new()
                    .num_threads(n)
                    .build_global()
                    .context("setting up the thread pool")?;
            }
            let mut sc = Scenario::from_file(&scenario)?.with_overrides(seed, duration)?;
            if let Some(b) = backend {
                sc.spec.field.backend = b;
            }
            let out = out.unwrap_or_else(|| {
                PathBuf::from("runs").join(scenario.file_stem().unwrap_or_default())
            });
            // Ctrl-C and SIGTERM end the run after the current step, with every output written.
            let stop = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
            let flag = stop.clone();
            ctrlc::set_handler(move || flag.store(true, std::sync::atomic::Ordering::Relaxed))
                .context("installing the Ctrl-C / SIGTERM handler")?;
            let report = run(
                &sc,
                &out,
                &RunOptions {
                    progress: !quiet,
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
        Command::Check { scenario } => {
            let sc = Scenario::from_file(&scenario)?;
            // What the bridge would refuse as it starts: calibration files that cannot be used.
            colcos_bridge::calibrate::RigCalibration::load(&sc)
                .with_context(|| format!("{}", scenario.display()))?;
            let a = sc.arena_size();
            writeln!(text, "{}: ok", scenario.display())?;
            writeln!(
                text,
                "  arena {} x {} m, {} s at dt {} s ({} steps), seed {}",
                a.x,
                a.y,
                sc.spec.duration,
                sc.spec.dt,
                sc.steps(),
                sc.spec.seed
            )?;
            for p in &sc.spec.pheromones {
                writeln!(
                    text,
                    "  pheromone {:?}: {:?} model, colour {:?}",
                    p.name, p.model, p.colour
                )?;
            }
            for g in &sc.spec.robots {
                writeln!(
                    text,
                    "  {} robot(s), role {:?}, behaviour {:?}",
                    g.count, g.role, g.behaviour
                )?;
            }
            Ok(())
        }
        Command::Behaviours => {
            use colcos::sim::behaviour::registry;
            writeln!(
                text,
                "A robot group names one with `behaviour = \"NAME\"` and sets its keys in `params = {{ ... }}`."
            )?;
            for (name, about) in registry::list() {
                writeln!(text, "\n{name}: {about}")?;
                for p in registry::params(name).unwrap_or_default() {
                    writeln!(
                        text,
                        "  {:18} {:24} default {:6} {}",
                        p.name, p.ty, p.default, p.meaning
                    )?;
                }
            }
            Ok(())
        }
    }
}
