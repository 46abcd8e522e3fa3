//! `summary.json`: the scenario's name and seed, step count, wall time and real-time factor of a run.
use super::RunReport;
use crate::error::SimError;
use crate::scenario::Scenario;
use std::path::Path;

/// Writes the summary of `report` to `path`; `total_wall_seconds` includes the output files.
pub(super) fn write(
    path: &Path,
    scenario: &Scenario,
    report: &RunReport,
    total_wall_seconds: f64,
) -> Result<(), SimError> {
    std::fs::write(path, text(scenario, report, total_wall_seconds))
        .map_err(|e| SimError::io(format!("writing {}", path.display()), e))
}

/// Formatted by hand: this crate has no JSON dependency, and the timings read best at fixed decimals.
fn text(scenario: &Scenario, report: &RunReport, total_wall_seconds: f64) -> String {
    format!(
        "{{\n  \"scenario\": {:?},\n  \"seed\": {},\n  \"steps\": {},\n  \"robots\": {},\n  \"sim_seconds\": {},\n  \"step_wall_seconds\": {:.4},\n  \"real_time_factor\": {:.2},\n  \"total_wall_seconds\": {:.3},\n  \"backend\": {:?},\n  \"interrupted\": {}\n}}\n",
        scenario.spec.name,
        scenario.spec.seed,
        report.steps,
        report.robots,
        report.sim_seconds,
        report.wall_seconds,
        report.real_time_factor(),
        total_wall_seconds,
        report.backend,
        report.interrupted
    )
}
