//! `colcos sweep SWEEP.toml`: a batch of scenario runs over axes of parameters and seeds (the
//! `colcos-sweep` library), with a progress bar, the results table, pictures and `summary.md`.
//! Ctrl-C (or SIGTERM) stops starting runs and exits with status 130, saying how many runs are in and
//! how to resume; a rerun (or `--resume`) into the same directory finishes the sweep.
pub mod data;
pub mod plots;
pub mod summary;

use anyhow::{Context, Result};
use colcos_sweep::effects::{Effect, axis_effects};
use colcos_sweep::{Plan, RunRow, SweepOptions, run_sweep};
use indicatif::{ProgressBar, ProgressStyle};
use std::io::Write as _;
use std::path::{Path, PathBuf};
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
    #[command(flatten)]
    pub pool: super::ThreadsArg,
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
    let out = args.out.clone().unwrap_or_else(|| default_out(&plan));
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
            threads: args.pool.threads,
            resume: args.resume,
            on_row: Some(&on_row),
            stop: Some(&stop),
        },
    )?;
    bar.finish_and_clear();
    let table = data::Table::read(&report.table)?;
    let effects = axis_effects(&plan, &rows_of(&table, &plan));
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
        &effects,
        plan.total(),
        plan.seeds.len(),
        &names,
    );
    let md_path = out.join("summary.md");
    std::fs::write(&md_path, md).with_context(|| format!("writing {}", md_path.display()))?;
    let rate = report.ran as f64 / report.wall_s.max(1e-9);
    // Written, not println!: a reader that closed the pipe (`| head`) must not turn into a panic.
    let mut text = String::new();
    if report.interrupted {
        text += &format!(
            "sweep {} interrupted: {} of {} runs are in {} ({} ran now); resume with: colcos sweep {} --out {} --resume\n",
            plan.name,
            table.rows.len(),
            report.total,
            report.table.display(),
            report.ran,
            args.sweep.display(),
            out.display()
        );
    } else {
        text += &format!(
            "sweep {}: {} runs ({} ran now at {:.1} runs/s, {} from an earlier run) in {:.1} s -> {}\n",
            plan.name,
            report.total,
            report.ran,
            rate,
            report.skipped,
            report.wall_s,
            report.table.display()
        );
    }
    text += &format!(
        "summary: {}, {} pictures in {}\n",
        md_path.display(),
        pictures.len(),
        out.join("plots").display()
    );
    for (axis, e) in plan.axes.iter().zip(&effects) {
        if !e.is_empty() && e.iter().all(|x| *x == Effect::None) {
            text += &format!(
                "note: axis `{}` changed no metric (identical results at every value): the model does not answer this question\n",
                axis.name
            );
        }
    }
    let mut stdout = std::io::stdout().lock();
    let _ = stdout.write_all(text.as_bytes());
    let _ = stdout.flush();
    if report.interrupted {
        // 130: the shell's code for a command ended by Ctrl-C; the table is resumable.
        std::process::exit(130);
    }
    Ok(())
}

/// The table's rows as the library's run rows (metric cells only), for the effects of the axes.
fn rows_of(t: &data::Table, plan: &Plan) -> Vec<RunRow> {
    let col = |name: &str| t.col(name);
    let (Some(id), Some(combo), Some(seed)) = (col("run_id"), col("combo"), col("seed")) else {
        return Vec::new();
    };
    let metrics: Vec<Option<usize>> = plan.metrics.columns.iter().map(|m| col(m)).collect();
    t.rows
        .iter()
        .filter(|r| (r[combo] as usize) < plan.combos.len())
        .map(|r| RunRow {
            id: r[id] as u64,
            combo: r[combo] as usize,
            seed: r[seed] as u64,
            metrics: metrics
                .iter()
                .map(|c| c.map(|c| r[c]).filter(|v| v.is_finite()))
                .collect(),
            wall_s: 0.0,
        })
        .collect()
}

/// The default output directory of a sweep.
pub fn default_out(plan: &Plan) -> PathBuf {
    Path::new("runs/sweeps").join(&plan.name)
}
