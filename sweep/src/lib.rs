//! colcos-sweep: batch scenario sweeps over `colcos-sim`.
//!
//! A sweep file ([`spec`]) names a base scenario, axes over any of its keys by path
//! (`pheromones[0].evaporation`), how they combine (a grid, a Latin hypercube, random points), the
//! seeds, the duration and the metrics. [`Plan`] turns it into runs, each run's scenario checked by the
//! scenario code before the first run starts; [`run_sweep`] runs them in parallel and appends one row
//! per finished run to a resumable CSV table ([`table`]). The same runs can be computed elsewhere
//! ([`run_ids`], what a Ray task calls) and appended to the same table. [`effects`] tells which axes
//! changed which metrics (an axis the model ignores gives identical runs at all its values).
//!
//! ```no_run
//! let plan = colcos_sweep::Plan::from_file("scenarios/sweeps/tiny.toml")?;
//! let report = colcos_sweep::run_sweep(&plan, "runs/tiny".as_ref(), Default::default())?;
//! println!("{} runs, table {}", report.total, report.table.display());
//! # Ok::<(), colcos_sweep::SweepError>(())
//! ```

pub mod axis;
pub mod effects;
pub mod error;
mod explain;
pub mod keypath;
pub mod metrics;
pub mod parquet_table;
pub mod plan;
pub mod runner;
pub mod spec;
pub mod table;

pub use error::SweepError;
pub use plan::Plan;
pub use runner::{
    RunRow, SweepOptions, SweepReport, Trace, run_ids, run_one, run_sweep, run_traced,
};
pub use table::ResultsTable;
