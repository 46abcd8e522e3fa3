//! `summary.md`: for each metric, the best and the worst setting (combination of axis values) by its
//! mean over seeds, with the 95 % interval, and the table's shape. An axis along which a metric does
//! not move is said to have no effect rather than named at its first value (where ties resolve).
use super::data::{Table, mean_ci, short};
use colcos_sweep::effects::Effect;
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

/// The settings of `metric`, labelled by the axes in `shown` only (the others do not move it).
fn settings(t: &Table, axes: &[String], shown: &[bool], metric: usize) -> Vec<Setting> {
    let Some(combo) = t.col("combo") else {
        return Vec::new();
    };
    let axis_cols: Vec<Option<usize>> = axes
        .iter()
        .zip(shown)
        .map(|(a, &s)| if s { t.col(a) } else { None })
        .collect();
    let mut by: BTreeMap<u64, (String, Vec<f64>)> = BTreeMap::new();
    for (row, text) in t.rows.iter().zip(&t.text) {
        let entry = by.entry(row[combo] as u64).or_insert_with(|| {
            let label = axes
                .iter()
                .zip(&axis_cols)
                .filter_map(|(a, c)| c.map(|c| (a, c)))
                .map(|(a, c)| match text[c].parse::<f64>() {
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

/// The summary's text; `effects[axis][metric]` says which axes move which metrics.
#[allow(clippy::too_many_arguments)]
pub fn markdown(
    name: &str,
    t: &Table,
    axes: &[String],
    metrics: &[String],
    effects: &[Vec<Effect>],
    runs: u64,
    seeds: usize,
    plots: &[String],
) -> String {
    let effect = |a: usize, m: usize| {
        effects
            .get(a)
            .and_then(|e| e.get(m))
            .copied()
            .unwrap_or(Effect::Untested)
    };
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
    for (a, name) in axes.iter().enumerate() {
        if !metrics.is_empty() && (0..metrics.len()).all(|m| effect(a, m) == Effect::None) {
            let _ = writeln!(
                s,
                "**`{name}`: no effect across this axis.** Runs that differ only in its value (same \
                 seed, same other axes) gave identical results for every metric: this sweep asks \
                 the model nothing about it.\n"
            );
        }
    }
    let _ = writeln!(
        s,
        "Best and worst setting of each metric by its mean over seeds (95 % interval, runs); axes \
         along which a metric did not move are left out of its settings:\n"
    );
    let _ = writeln!(
        s,
        "| metric | better | best setting | mean | worst setting | mean | no effect across |"
    );
    let _ = writeln!(s, "| --- | --- | --- | --- | --- | --- | --- |");
    for (mi, m) in metrics.iter().enumerate() {
        let Some(c) = t.col(m) else { continue };
        let shown: Vec<bool> = (0..axes.len())
            .map(|a| effect(a, mi) != Effect::None)
            .collect();
        let none: Vec<String> = axes
            .iter()
            .zip(&shown)
            .filter(|(_, s)| !**s)
            .map(|(a, _)| format!("`{a}`"))
            .collect();
        let none = none.join(", ");
        let all = settings(t, axes, &shown, c);
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
            let _ = writeln!(
                s,
                "| `{m}` | {dir} | every setting the same | {bv} | | | {none} |"
            );
            continue;
        }
        let _ = writeln!(s, "| `{m}` | {dir} | {bl} | {bv} | {wl} | {wv} | {none} |");
    }
    if !plots.is_empty() {
        let _ = writeln!(s, "\nPictures (`plots/`):\n");
        for p in plots {
            let _ = writeln!(s, "- [{p}](plots/{p})");
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two axes x two seeds: `e` moves nothing, `n` moves `s_mean`.
    fn table() -> Table {
        let columns = ["run_id", "combo", "e", "n", "seed", "s_mean", "wall_s"];
        let mut text = Vec::new();
        let mut id = 0;
        for (combo, (e, n)) in [("2.5", "1"), ("2.5", "3"), ("5", "1"), ("5", "3")]
            .iter()
            .enumerate()
        {
            for seed in 0..2 {
                let s = if *n == "1" { 0.2 + seed as f64 } else { 0.5 };
                text.push(
                    [
                        id.to_string(),
                        combo.to_string(),
                        e.to_string(),
                        n.to_string(),
                        seed.to_string(),
                        s.to_string(),
                        "0.01".into(),
                    ]
                    .to_vec(),
                );
                id += 1;
            }
        }
        Table {
            columns: columns.map(String::from).to_vec(),
            rows: text
                .iter()
                .map(|r| r.iter().map(|c| c.parse().unwrap_or(f64::NAN)).collect())
                .collect(),
            text,
        }
    }

    #[test]
    fn an_axis_with_no_effect_is_not_named_at_its_first_value() {
        let axes = ["e".to_string(), "n".to_string()];
        // The summary of `table()` (8 runs, 2 seeds) with axis `e` found to have `e_effect`.
        let summary = |e_effect: Effect| {
            let effects = vec![vec![e_effect], vec![Effect::Changes]];
            markdown(
                "t",
                &table(),
                &axes,
                &["s_mean".into()],
                &effects,
                8,
                2,
                &[],
            )
        };
        let md = summary(Effect::None);
        assert!(md.contains("**`e`: no effect across this axis.**"), "{md}");
        assert!(
            md.contains("| `s_mean` | lower | n = 3 | 0.5 +- 0 (2) | n = 1 | 0.7 +- "),
            "{md}"
        );
        assert!(md.contains("| `e` |"), "{md}");
        assert!(!md.contains("e = 2.5"), "{md}");
        // Untested axes (sampled sweeps) keep their values in the settings.
        let md = summary(Effect::Untested);
        assert!(
            md.contains("e = 2.5, n = 3") && !md.contains("no effect across this axis"),
            "{md}"
        );
    }
}
