//! docs/sweeps.md documents every metric and every key of the sweep file: a new one fails here until
//! it is described.
use colcos_sweep::metrics::METRICS;
use colcos_sweep::spec::{AxisSpec, MetricOptions, SweepSpec};

fn docs() -> String {
    std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../docs/sweeps.md")).unwrap()
}

fn keys_of<T: serde::Serialize>(value: &T) -> Vec<String> {
    toml::Table::try_from(value)
        .unwrap()
        .keys()
        .cloned()
        .collect()
}

#[test]
fn every_metric_and_key_is_documented() {
    let docs = docs();
    let mut missing = Vec::new();
    for (name, _) in METRICS {
        if !docs.contains(&format!("| `{name}` |")) {
            missing.push(format!("metric {name}"));
        }
    }
    let spec: SweepSpec = toml::from_str(
        "scenario = \"x.toml\"\nname = \"n\"\nduration = 1.0\nsamples = 2\nmetrics = [\"s_mean\"]\n",
    )
    .unwrap();
    let axis: AxisSpec =
        toml::from_str("key = \"a\"\nkeys = [\"b\"]\nname = \"c\"\nvalues = [1]\nrange = { from = 0.0, to = 1.0 }\ndraw = { distribution = \"uniform\" }\n")
            .unwrap();
    for k in keys_of(&spec)
        .into_iter()
        .chain(keys_of(&axis))
        .chain(keys_of(&MetricOptions::default()))
        .chain(["axes".to_string()])
    {
        // A table row's first cell: `key` alone or among others (`leader_role`, `follower_role`).
        if !docs.contains(&format!("| `{k}` |"))
            && !docs.contains(&format!("| `{k}`, "))
            && !docs.contains(&format!(", `{k}` |"))
        {
            missing.push(format!("key {k}"));
        }
    }
    assert!(missing.is_empty(), "not in docs/sweeps.md: {missing:?}");
}
