//! Every sweep shipped in `scenarios/sweeps/` asks a question the model answers: run briefly (each axis
//! at its two extreme values, every combination of those, the sweep's first ten seeds at most, its own
//! duration), every axis must change at least one metric. Runs of one seed that differ in one axis only share their
//! random streams, so an axis that acts on nothing gives identical rows (`colcos_sweep::effects`).
use colcos_sweep::Plan;
use colcos_sweep::effects::{Effect, axis_effects};
use std::path::{Path, PathBuf};

/// Seeds at most: an effect that shows in some runs only (an alarm that ends before the run does)
/// needs a few.
const SEEDS: usize = 10;

fn sweeps_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenarios/sweeps")
}

fn shipped() -> Vec<PathBuf> {
    let files = colcos_testkit::scenarios::shipped(&["scenarios/sweeps"]);
    assert!(files.len() >= 5, "{files:?}");
    files
}

/// An axis value's order: numbers by value, anything else as written.
fn order(v: &toml::Value) -> f64 {
    v.as_float()
        .or_else(|| v.as_integer().map(|i| i as f64))
        .unwrap_or(f64::NAN)
}

/// The same sweep on a grid of each axis's two extremes (a sampled axis: its 5 % and 95 % quantiles),
/// with its first `SEEDS` seeds.
fn brief(text: &str, file: &str) -> Plan {
    let plan = Plan::from_toml_str(text, file, &sweeps_dir()).unwrap();
    let mut t: toml::Table = text.parse().unwrap();
    let sampled = t
        .get("sampling")
        .is_some_and(|s| s.as_str() != Some("grid"));
    if let Some(toml::Value::Array(axes)) = t.get_mut("axes") {
        for (i, axis) in axes.iter_mut().enumerate() {
            let ends = if sampled {
                vec![
                    plan.axes[i].at_quantile(0.05),
                    plan.axes[i].at_quantile(0.95),
                ]
            } else {
                let mut values: Vec<toml::Value> =
                    plan.combos.iter().map(|c| c[i].clone()).collect();
                values.sort_by(|a, b| order(a).total_cmp(&order(b)));
                vec![values[0].clone(), values[values.len() - 1].clone()]
            };
            let axis = axis.as_table_mut().unwrap();
            for k in ["values", "range", "draw"] {
                axis.remove(k);
            }
            axis.insert("values".into(), toml::Value::Array(ends));
        }
    }
    t.remove("samples");
    t.insert("sampling".into(), "grid".into());
    let seeds: Vec<i64> = plan.seeds.iter().take(SEEDS).map(|&s| s as i64).collect();
    t.insert("seeds".into(), seeds.into());
    Plan::from_toml_str(&toml::to_string(&t).unwrap(), file, &sweeps_dir()).unwrap()
}

/// The axes of a sweep that change no metric, each with what it was run at.
fn inert_axes(text: &str, file: &str) -> Vec<String> {
    let plan = brief(text, file);
    let ids: Vec<u64> = (0..plan.total()).collect();
    let rows = colcos_sweep::run_ids(&plan, &ids).unwrap();
    let effects = axis_effects(&plan, &rows);
    let mut inert = Vec::new();
    for (axis, e) in plan.axes.iter().zip(&effects) {
        assert!(
            !e.contains(&Effect::Untested),
            "{file}: axis {} was not tested",
            axis.name
        );
        if e.iter().all(|x| *x == Effect::None) {
            inert.push(format!(
                "{file}: axis `{}` changed none of {:?} ({} runs: {} combinations x {} seeds)",
                axis.name,
                plan.metrics.columns,
                rows.len(),
                plan.combos.len(),
                plan.seeds.len()
            ));
        }
    }
    inert
}

#[test]
fn every_axis_of_every_shipped_sweep_changes_a_metric() {
    let mut inert = Vec::new();
    for path in shipped() {
        let text = std::fs::read_to_string(&path).unwrap();
        let file = path.file_name().unwrap().to_string_lossy().into_owned();
        // The sweep as shipped plans.
        Plan::from_toml_str(&text, &file, &sweeps_dir()).unwrap();
        inert.extend(inert_axes(&text, &file));
    }
    assert!(inert.is_empty(), "{}", inert.join("\n"));
}

#[test]
fn an_axis_the_model_ignores_is_caught() {
    // The AGP source follows the leader and is refreshed every step: its evaporation never acts.
    let text = r#"
scenario = "../case2_alarm.toml"
duration = 10.0
metrics = ["s_mean", "nn_distance", "field_mass"]
[[axes]]
name = "agp_evaporation"
keys = ["pheromones[0].evaporation", "robots[0].emits[0].evaporation"]
range = { from = 2.5, to = 40.0, steps = 5, scale = "log" }
[[axes]]
name = "followers"
key = "robots[1].count"
values = [1, 3]
"#;
    let inert = inert_axes(text, "agp_evaporation.toml");
    assert_eq!(inert.len(), 1, "{inert:?}");
    assert!(inert[0].contains("`agp_evaporation`"), "{inert:?}");
}
