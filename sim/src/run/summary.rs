//! `summary.json`: the scenario's name and seed, step count, wall time and real-time factor of a run,
//! and the GIF's frame interval.
use super::RunReport;
use crate::error::SimError;
use crate::scenario::Scenario;
use std::path::Path;

/// Writes the summary of `report` to `path`.
pub(super) fn write(path: &Path, scenario: &Scenario, report: &RunReport) -> Result<(), SimError> {
    std::fs::write(path, text(scenario, report))
        .map_err(|e| SimError::io(format!("writing {}", path.display()), e))
}

/// Formatted by hand: this crate has no JSON dependency, and the timings read best at fixed decimals.
fn text(scenario: &Scenario, report: &RunReport) -> String {
    // The GIF's seconds between frames (`null`: none written) and how many `gif_interval`s that is.
    let (gif_interval, gif_thinned) = report.gif.map_or(("null".into(), 0), |g| {
        (format!("{}", g.interval), g.thinned)
    });
    format!(
        "{{\n  \"scenario\": {:?},\n  \"seed\": {},\n  \"steps\": {},\n  \"robots\": {},\n  \"sim_seconds\": {},\n  \"step_wall_seconds\": {:.4},\n  \"real_time_factor\": {:.2},\n  \"total_wall_seconds\": {:.3},\n  \"overall_real_time_factor\": {:.2},\n  \"gif_interval\": {},\n  \"gif_thinned\": {},\n  \"backend\": {:?},\n  \"interrupted\": {}\n}}\n",
        scenario.spec.name,
        scenario.spec.seed,
        report.steps,
        report.robots,
        report.sim_seconds,
        report.wall_seconds,
        report.real_time_factor(),
        report.total_wall_seconds,
        report.overall_real_time_factor(),
        gif_interval,
        gif_thinned,
        report.backend,
        report.interrupted
    )
}
