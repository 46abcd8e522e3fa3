//! `colcos sweep SWEEP.toml`: a batch of scenario runs over axes of parameters and seeds (the
//! `colcos-sweep` library), with a progress bar, the results table, pictures and `summary.md`.
//! Ctrl-C stops starting runs; a rerun (or `--resume`) into the same directory finishes the sweep.
pub mod data;
pub mod plots;
pub mod summary;

use anyhow::{Context, Result};
use colcos_sweep::{Plan, SweepOptions, run_sweep};
use indicatif::{ProgressBar, ProgressStyle};
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

/// Arguments of `colcos sweep`.
#[derive(Clone, Debug, clap::Args)]
pub struct SweepArgs {
    /// Sweep file (TOML; docs/sweeps.md).
    pub sweep: PathBuf,
    /// Output directory [default: runs/sweeps/<sweep name>].
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Worker threads, 1 to 1024 (default: all cores). Results do not depend on it.
    #[arg(long, value_parser = clap::builder::RangedU64ValueParser::<usize>::new().range(1..=1024))]
    pub threads: Option<usize>,
    /// Continue the table in the output directory (an error if there is none). A rerun into the same
    /// directory continues it too.
    #[arg(long)]
    pub resume: bool,
    /// No progress bar.
    #[arg(long)]
    pub quiet: bool,
}

/// Runs the sweep and writes its pictures and summary.
pub fn main(args: SweepArgs) -> Result<()> {
    let plan = Plan::from_file(&args.sweep)?;
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("runs/sweeps").join(&plan.name));
    let stop = Arc::new(AtomicBool::new(false));
    {
        let stop = stop.clone();
        // Another handler may already be installed (tests calling this twice): then Ctrl-C just kills.
        let _ = ctrlc::set_handler(move || stop.store(true, Ordering::Relaxed));
    }
    let bar = if args.quiet {
        ProgressBar::hidden()
    } else {
        let b = ProgressBar::new(plan.total());
        b.set_style(
            ProgressStyle::with_template("{bar:40} {pos}/{len} runs  {per_sec}  ETA {eta}  {msg}")
                .unwrap_or_else(|_| ProgressStyle::default_bar()),
        );
        b
    };
    let first = std::sync::OnceLock::new();
    let on_row = |done: u64, _total: u64| {
        // The first call reports the rows found in the table: start the bar's rate from there.
        if first.set(done).is_ok() {
            bar.set_position(done);
            bar.reset_eta();
            if done > 0 {
                bar.set_message(format!("({done} from an earlier run)"));
            }
        } else {
            bar.set_position(done);
        }
    };
    let report = run_sweep(
        &plan,
        &out,
        SweepOptions {
            threads: args.threads,
            resume: args.resume,
            on_row: Some(&on_row),
            stop: Some(&stop),
        },
    )?;
    bar.finish_and_clear();
    let table = data::Table::read(&report.table)?;
    let axes: Vec<plots::AxisInfo> = plan
        .axes
        .iter()
        .map(|a| plots::AxisInfo {
            name: a.name.clone(),
            log: a.log,
        })
        .collect();
    let pictures = plots::all(&table, &axes, &plan.metrics.columns, &out.join("plots"))
        .context("drawing the sweep's pictures")?;
    let names: Vec<String> = pictures
        .iter()
        .filter_map(|p| p.file_name().map(|n| n.to_string_lossy().into_owned()))
        .collect();
    let axis_names: Vec<String> = plan.axes.iter().map(|a| a.name.clone()).collect();
    let md = summary::markdown(
        &plan.name,
        &table,
        &axis_names,
        &plan.metrics.columns,
        plan.total(),
        plan.seeds.len(),
        &names,
    );
    let md_path = out.join("summary.md");
    std::fs::write(&md_path, md).with_context(|| format!("writing {}", md_path.display()))?;
    let rate = report.ran as f64 / report.wall_s.max(1e-9);
    println!(
        "sweep {}: {} runs ({} ran now at {:.1} runs/s, {} from an earlier run) in {:.1} s -> {}",
        plan.name,
        report.total,
        report.ran,
        rate,
        report.skipped,
        report.wall_s,
        report.table.display()
    );
    println!(
        "summary: {}, {} pictures in {}",
        md_path.display(),
        pictures.len(),
        out.join("plots").display()
    );
    if report.interrupted {
        println!(
            "interrupted: {} of {} runs done; rerun the same command (or add --resume) to finish",
            table.rows.len(),
            report.total
        );
    }
    Ok(())
}
