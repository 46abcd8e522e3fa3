//! `summary.md`: for each metric, the best and the worst setting (combination of axis values) by its
//! mean over seeds, with the 95 % interval, and the table's shape.
use super::data::{Table, mean_ci, short};
use std::collections::BTreeMap;
use std::fmt::Write as _;

/// Whether a larger value of a metric column is better (arrivals, coverage) or worse (distances, times,
/// collisions).
pub fn higher_is_better(metric: &str) -> bool {
    matches!(metric, "arrivals" | "arrivals_food" | "area_covered")
        || metric.starts_with("field_mass_")
}

/// One setting's statistics.
struct Setting {
    label: String,
    mean: f64,
    ci: f64,
    n: usize,
}

fn settings(t: &Table, axes: &[String], metric: usize) -> Vec<Setting> {
    let Some(combo) = t.col("combo") else {
        return Vec::new();
    };
    let axis_cols: Vec<usize> = axes.iter().filter_map(|a| t.col(a)).collect();
    let mut by: BTreeMap<u64, (String, Vec<f64>)> = BTreeMap::new();
    for (row, text) in t.rows.iter().zip(&t.text) {
        let entry = by.entry(row[combo] as u64).or_insert_with(|| {
            let label = axes
                .iter()
                .zip(&axis_cols)
                .map(|(a, &c)| match text[c].parse::<f64>() {
                    Ok(v) => format!("{a} = {}", short(v)),
                    Err(_) => format!("{a} = {}", text[c]),
                })
                .collect::<Vec<_>>()
                .join(", ");
            (
                if label.is_empty() {
                    "(the base scenario)".into()
                } else {
                    label
                },
                Vec::new(),
            )
        });
        entry.1.push(row[metric]);
    }
    by.into_values()
        .filter_map(|(label, v)| mean_ci(&v).map(|(mean, ci, n)| Setting { label, mean, ci, n }))
        .collect()
}

/// The summary's text.
pub fn markdown(
    name: &str,
    t: &Table,
    axes: &[String],
    metrics: &[String],
    runs: u64,
    seeds: usize,
    plots: &[String],
) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "# Sweep `{name}`\n");
    let _ = writeln!(
        s,
        "{} of {runs} runs in `results.csv` ({} settings x {seeds} seeds); axes: {}.\n",
        t.rows.len(),
        runs as usize / seeds.max(1),
        if axes.is_empty() {
            "none".into()
        } else {
            axes.iter()
                .map(|a| format!("`{a}`"))
                .collect::<Vec<_>>()
                .join(", ")
        }
    );
    let _ = writeln!(
        s,
        "Best and worst setting of each metric by its mean over seeds (95 % interval, runs):\n"
    );
    let _ = writeln!(
        s,
        "| metric | better | best setting | mean | worst setting | mean |"
    );
    let _ = writeln!(s, "| --- | --- | --- | --- | --- | --- |");
    for m in metrics {
        let Some(c) = t.col(m) else { continue };
        let all = settings(t, axes, c);
        let up = higher_is_better(m);
        let key = |x: &Setting| if up { x.mean } else { -x.mean };
        // The first of equal settings wins, so the summary does not depend on float ties' order.
        let best = all
            .iter()
            .reduce(|a, b| if key(b) > key(a) { b } else { a });
        let worst = all
            .iter()
            .reduce(|a, b| if key(b) < key(a) { b } else { a });
        let cell = |x: Option<&Setting>| match x {
            Some(x) => (
                x.label.clone(),
                format!("{} +- {} ({})", short(x.mean), short(x.ci), x.n),
            ),
            None => ("-".into(), "no values".into()),
        };
        let (bl, bv) = cell(best);
        let (wl, wv) = cell(worst);
        let dir = if up { "higher" } else { "lower" };
        if let (Some(b), Some(w)) = (best, worst)
            && b.mean == w.mean
        {
            let _ = writeln!(s, "| `{m}` | {dir} | every setting the same | {bv} | | |");
            continue;
        }
        let _ = writeln!(s, "| `{m}` | {dir} | {bl} | {bv} | {wl} | {wv} |");
    }
    if !plots.is_empty() {
        let _ = writeln!(s, "\nPictures (`plots/`):\n");
        for p in plots {
            let _ = writeln!(s, "- [{p}](plots/{p})");
        }
    }
    s
}
