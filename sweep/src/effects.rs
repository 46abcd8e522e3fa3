//! Which axes change which metrics. Runs of one seed that differ only in one axis's value share their
//! random streams (common random numbers), so an axis that acts on nothing gives bit-identical metrics
//! at all its values: an exact test, with no statistics, wherever the table holds such pairs of runs (a
//! grid). Sampled sweeps (Latin hypercube, random points) rarely do: their axes stay untested.
use crate::plan::Plan;
use crate::runner::{RunRow, value_text};
use std::collections::HashMap;

/// What one axis does to one metric column.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Effect {
    /// Some two runs that differ only in this axis's value differ in the metric.
    Changes,
    /// Every such pair has the same value: across this axis the metric does not move.
    None,
    /// No such pair in the rows (sampled points, an axis with one value).
    Untested,
}

/// `[axis][metric column]` over `rows` (any subset of the sweep's runs, in any order).
pub fn axis_effects(plan: &Plan, rows: &[RunRow]) -> Vec<Vec<Effect>> {
    let width = rows.first().map_or(0, |r| r.metrics.len());
    (0..plan.axes.len())
        .map(|axis| {
            // Runs grouped by their seed and the values of the other axes.
            let mut groups: HashMap<(u64, Vec<String>), Vec<&RunRow>> = HashMap::new();
            for r in rows {
                let others = plan.combos[r.combo]
                    .iter()
                    .enumerate()
                    .filter(|&(k, _)| k != axis)
                    .map(|(_, v)| value_text(v))
                    .collect();
                groups.entry((r.seed, others)).or_default().push(r);
            }
            let tested: Vec<&Vec<&RunRow>> = groups
                .values()
                .filter(|g| {
                    let v0 = value_text(&plan.combos[g[0].combo][axis]);
                    g.iter()
                        .any(|r| value_text(&plan.combos[r.combo][axis]) != v0)
                })
                .collect();
            (0..width)
                .map(|m| {
                    if tested.is_empty() {
                        return Effect::Untested;
                    }
                    let cell = |r: &RunRow| r.metrics[m].filter(|v| !v.is_nan()).map(f64::to_bits);
                    let moves = tested
                        .iter()
                        .any(|g| g.iter().any(|r| cell(r) != cell(g[0])));
                    if moves { Effect::Changes } else { Effect::None }
                })
                .collect()
        })
        .collect()
}

/// The axes that change no metric at all in `rows` (tested ones only).
pub fn inert_axes(plan: &Plan, rows: &[RunRow]) -> Vec<usize> {
    axis_effects(plan, rows)
        .iter()
        .enumerate()
        .filter(|(_, e)| !e.is_empty() && e.iter().all(|x| *x == Effect::None))
        .map(|(i, _)| i)
        .collect()
}
