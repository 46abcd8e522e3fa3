//! Every kind of bad sweep file is refused before anything runs, with the key path and the value.
use colcos_sweep::Plan;
use std::path::{Path, PathBuf};

fn dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenarios/sweeps")
}

const HEAD: &str = "scenario = \"../case2_alarm.toml\"\nduration = 1.0\n";

fn plan(body: &str) -> Result<Plan, String> {
    let p = Plan::from_toml_str(&format!("{HEAD}{body}"), "bad.toml", &dir())
        .map_err(|e| e.to_string())?;
    // What a sweep does before its first run: every combination's scenario checked.
    p.check_all().map_err(|e| e.to_string())?;
    Ok(p)
}

#[track_caller]
fn refused(body: &str, expect: &[&str]) {
    let e = match plan(body) {
        Ok(_) => panic!("accepted:\n{body}"),
        Err(e) => e,
    };
    for x in expect {
        assert!(
            e.contains(x),
            "error for\n{body}\nis\n{e}\nwhich does not contain {x:?}"
        );
    }
}

#[test]
fn a_good_sweep_is_accepted() {
    let p = plan(
        "metrics = [\"s_mean\"]\nseeds = [3, 5]\n[[axes]]\nkey = \"robots[1].count\"\nrange = { from = 1, to = 4, steps = 4 }\n",
    )
    .unwrap();
    assert_eq!(p.total(), 8);
    // An integral float from a range into an integer key becomes an integer.
    assert_eq!(p.scenario(7).unwrap().spec.robots[1].count, 4);
    assert_eq!(p.scenario(7).unwrap().spec.seed, 5);
}

#[test]
fn file_format_errors() {
    refused(
        "metrics = [\"s_mean\"]\ncolour = 3\n",
        &["unknown field `colour`"],
    );
    refused(
        "metrics = [\"s_mean\"]\n[[axes]]\nkey = \"tracker.latency\"\nvalue = [1]\n",
        &["axes[0]", "unknown field `value`"],
    );
    refused("metrics = \"s_mean\"\n", &["metrics", "invalid type"]);
    refused("metrics = [\"s_mean\"]\nseeds = -1\n", &["seeds"]);
    refused(
        "metrics = [\"s_mean\"]\nsampling = \"sobol\"\n",
        &["sampling", "sobol"],
    );
    refused("metrics = [\"s_mean\"\n", &["invalid sweep file bad.toml"]);
    refused(
        "metrics = [\"s_mean\"]\n[metric_options]\nsample_evry = 0.1\n",
        &["metric_options", "unknown field `sample_evry`"],
    );
}

#[test]
fn bad_top_level_values() {
    refused(
        "metrics = [\"s_mean\"]\nseeds = 0\n",
        &["invalid sweep bad.toml: `seeds` = 0"],
    );
    refused("metrics = [\"s_mean\"]\nseeds = []\n", &["`seeds` = []"]);
    refused(
        "metrics = [\"s_mean\"]\nseeds = [1, 2, 1]\n",
        &["`seeds[2]` = 1", "twice"],
    );
    let e = Plan::from_toml_str(
        "scenario = \"../case2_alarm.toml\"\nduration = -3.0\nmetrics = [\"s_mean\"]\n",
        "x.toml",
        &dir(),
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("`duration` = -3"), "{e}");
    refused("metrics = []\n", &["`metrics` = []"]);
    refused(
        "metrics = [\"s_mena\"]\n",
        &["`metrics[0]` = \"s_mena\"", "unknown metric", "s_mean"],
    );
    refused(
        "metrics = [\"s_mean\", \"s_mean\"]\n",
        &["`metrics[1]`", "twice"],
    );
    refused(
        "metrics = [\"s_mean\"]\nsampling = \"latin_hypercube\"\n",
        &["`samples`", "latin_hypercube"],
    );
    refused(
        "metrics = [\"s_mean\"]\nsamples = 4\n",
        &["`samples` = 4", "only for"],
    );
    refused(
        "scenario = \"nowhere.toml\"\nmetrics = [\"s_mean\"]\n",
        &["duplicate key"],
    );
}

#[test]
fn a_missing_base_scenario_is_named() {
    let e = Plan::from_toml_str(
        "scenario = \"nowhere.toml\"\nmetrics = [\"s_mean\"]\n",
        "x.toml",
        &dir(),
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("nowhere.toml"), "{e}");
}

#[test]
fn bad_axes() {
    refused(
        "metrics = [\"s_mean\"]\n[[axes]]\nvalues = [1]\n",
        &["`axes[0]`", "needs `key`"],
    );
    refused(
        "metrics = [\"s_mean\"]\n[[axes]]\nkey = \"a\"\nkeys = [\"b\"]\nvalues = [1]\n",
        &["`axes[0].key` = \"a\"", "not both"],
    );
    refused(
        "metrics = [\"s_mean\"]\n[[axes]]\nkey = \"robots[x].count\"\nvalues = [1]\n",
        &["`axes[0].key` = \"robots[x].count\"", "not an array index"],
    );
    refused(
        "metrics = [\"s_mean\"]\n[[axes]]\nkey = \"robots[1].count\"\n",
        &["`axes[0]`", "exactly one of"],
    );
    refused(
        "metrics = [\"s_mean\"]\n[[axes]]\nkey = \"robots[1].count\"\nvalues = [1]\nrange = { from = 1.0, to = 2.0, steps = 2 }\n",
        &["exactly one of"],
    );
    refused(
        "metrics = [\"s_mean\"]\n[[axes]]\nkey = \"robots[1].count\"\nvalues = []\n",
        &["`axes[0].values` = []"],
    );
    refused(
        "metrics = [\"s_mean\"]\n[[axes]]\nkey = \"tracker.latency\"\nvalues = [nan]\n",
        &["`axes[0].values[0]` = nan"],
    );
    refused(
        "metrics = [\"s_mean\"]\n[[axes]]\nkey = \"tracker.latency\"\nrange = { from = 0.0, to = 0.1 }\n",
        &["`axes[0].range.steps`", "grid"],
    );
    refused(
        "metrics = [\"s_mean\"]\n[[axes]]\nkey = \"tracker.latency\"\nrange = { from = 0.0, to = 0.1, steps = 3, scale = \"log\" }\n",
        &["`axes[0].range.from` = 0", "log"],
    );
    refused(
        "metrics = [\"s_mean\"]\n[[axes]]\nkey = \"tracker.latency\"\nrange = { from = 0.1, to = 0.2, steps = 0 }\n",
        &["`axes[0].range.steps` = 0"],
    );
    refused(
        "metrics = [\"s_mean\"]\n[[axes]]\nkey = \"tracker.latency\"\ndraw = { distribution = \"uniform\", low = 0.1 }\n",
        &["`axes[0].draw.high`", "missing"],
    );
    refused(
        "metrics = [\"s_mean\"]\n[[axes]]\nkey = \"tracker.latency\"\ndraw = { distribution = \"uniform\", low = 0.2, high = 0.1, count = 3 }\n",
        &["`axes[0].draw.high` = 0.1"],
    );
    refused(
        "metrics = [\"s_mean\"]\n[[axes]]\nkey = \"tracker.latency\"\ndraw = { distribution = \"normal\", mean = 0.1, sd = 0.0, count = 3 }\n",
        &["`axes[0].draw.sd` = 0"],
    );
    refused(
        "metrics = [\"s_mean\"]\n[[axes]]\nkey = \"tracker.latency\"\ndraw = { distribution = \"normal\", mean = 0.1, sd = 0.01, low = 0.0, count = 3 }\n",
        &["`axes[0].draw.low` = 0", "not a parameter"],
    );
    refused(
        "metrics = [\"s_mean\"]\n[[axes]]\nkey = \"tracker.latency\"\ndraw = { distribution = \"gamma\", count = 3 }\n",
        &["axes[0].draw.distribution", "gamma"],
    );
    refused(
        "metrics = [\"s_mean\"]\n[[axes]]\nkey = \"a\"\nvalues = [1]\n[[axes]]\nkey = \"a\"\nvalues = [2]\n",
        &["`axes[1].name` = \"a\"", "axes[0]"],
    );
    refused(
        "metrics = [\"s_mean\"]\n[[axes]]\nkey = \"a\"\nname = \"s_mean\"\nvalues = [1]\n",
        &["`axes[0].name` = \"s_mean\"", "metric column"],
    );
}

/// An error about a combination's scenario: one line, naming the sweep file, the axis, its key and
/// value, never a line of the generated scenario or a Rust type name.
#[track_caller]
fn axis_error(body: &str, expect: &[&str]) {
    refused(body, &["invalid sweep bad.toml: "]);
    let e = plan(body).err().unwrap();
    assert!(!e.contains('\n'), "more than one line:\n{e}");
    for bad in [
        "TOML parse error",
        "line ",
        "Spec",
        "usize",
        "f32",
        "<text>",
        " | ",
    ] {
        assert!(!e.contains(bad), "{e}\nshows {bad:?}");
    }
    refused(body, expect);
}

#[test]
fn keys_the_scenario_does_not_have() {
    axis_error(
        "metrics = [\"s_mean\"]\n[[axes]]\nkey = \"robots[7].count\"\nvalues = [1]\n",
        &["axes[0] sets robots[7].count = 1", "3 entries"],
    );
    axis_error(
        "metrics = [\"s_mean\"]\n[[axes]]\nkey = \"robots.count\"\nvalues = [1]\n",
        &["axes[0] sets robots.count = 1", "index it"],
    );
    axis_error(
        "metrics = [\"s_mean\"]\n[[axes]]\nkey = \"duration.x\"\nvalues = [1]\n",
        &["axes[0] sets duration.x = 1", "not a table"],
    );
    // A key the scenario format does not know: the keys its table takes, not the generated file's line.
    axis_error(
        "metrics = [\"s_mean\"]\n[[axes]]\nkey = \"tracker.latencyy\"\nvalues = [0.1]\n",
        &[
            "axes[0] sets tracker.latencyy = 0.1",
            "no key `tracker.latencyy`",
            "`latency`",
        ],
    );
    axis_error(
        "metrics = [\"s_mean\"]\n[[axes]]\nname = \"speed\"\nkey = \"robots[1].params.speedd\"\nvalues = [0.1]\n",
        &[
            "axes[0] (speed) sets robots[1].params.speedd = 0.1",
            "speedd",
        ],
    );
    // A whole table set to a number: which keys are inside it.
    axis_error(
        "metrics = [\"s_mean\"]\n[[axes]]\nkey = \"robots[1]\"\nvalues = [3]\n",
        &["axes[0] sets robots[1] = 3", "a table", "`robots[1].count`"],
    );
}

#[test]
fn a_bad_value_deep_in_the_grid_names_its_axis() {
    axis_error(
        "metrics = [\"s_mean\"]\nseeds = 2\n[[axes]]\nkey = \"tracker.latency\"\nvalues = [0.02, 0.04]\n[[axes]]\nname = \"agp_e\"\nkey = \"pheromones[0].evaporation\"\nvalues = [5.0, 10.0, -1.0]\n",
        &[
            "axes[1] (agp_e) sets pheromones[0].evaporation = -1.0 (combination 2)",
            "must be a finite number > 0",
        ],
    );
    // A wrong type for the scenario key, and a value out of an integer key's range.
    axis_error(
        "metrics = [\"s_mean\"]\n[[axes]]\nkey = \"robots[1].count\"\nvalues = [2, \"many\"]\n",
        &[
            "axes[0] sets robots[1].count = \"many\" (combination 1)",
            "string",
        ],
    );
    axis_error(
        "metrics = [\"s_mean\"]\n[[axes]]\nkey = \"robots[1].count\"\nvalues = [1, -3]\n",
        &["combination 1", "robots[1].count = -3", "an integer >= 0"],
    );
    // Several keys: the one the scenario refuses.
    axis_error(
        "metrics = [\"s_mean\"]\n[[axes]]\nname = \"agp_e\"\nkeys = [\"pheromones[0].evaporation\", \"robots[0].emits[0].evaporation\"]\nvalues = [0.0]\n",
        &["axes[0] (agp_e) sets pheromones[0].evaporation = 0.0"],
    );
}

#[test]
fn two_axes_on_one_key_are_refused_naming_both() {
    refused(
        "metrics = [\"s_mean\"]\n[[axes]]\nkey = \"tracker.latency\"\nvalues = [0.02]\n[[axes]]\nname = \"lag\"\nkey = \"tracker.latency\"\nvalues = [0.1]\n",
        &[
            "invalid sweep bad.toml",
            "`axes[1].key` = \"tracker.latency\"",
            "axes[1] (lag) and axes[0] both set `tracker.latency`",
        ],
    );
    // One key inside the other's table, and one key twice in one axis's `keys`.
    refused(
        "metrics = [\"s_mean\"]\n[[axes]]\nname = \"e\"\nkeys = [\"pheromones[0].evaporation\", \"robots[0].emits[0].evaporation\"]\nvalues = [5.0]\n[[axes]]\nname = \"agp\"\nkey = \"robots[0].emits[0]\"\nvalues = [{ pheromone = \"AGP\", k = 0.5, sigma = [0.4, 0.4], evaporation = 10.0 }]\n",
        &["`axes[1].key`", "axes[1] (agp) and axes[0] (e) both set"],
    );
    refused(
        "metrics = [\"s_mean\"]\n[[axes]]\nname = \"e\"\nkeys = [\"tracker.latency\", \"tracker.latency\"]\nvalues = [0.1]\n",
        &["`axes[0].keys[1]`", "the same axis"],
    );
}

#[test]
fn bad_metric_options() {
    refused(
        "metrics = [\"s_mean\"]\n[metric_options]\nsample_every = 0.0\n",
        &["`metric_options.sample_every` = 0"],
    );
    refused(
        "metrics = [\"arrivals\"]\n",
        &["`metric_options.arrival_points` = []"],
    );
    refused(
        "metrics = [\"arrivals\"]\n[metric_options]\narrival_points = [[0.1, 0.1]]\nfood_points = [2]\n",
        &["`metric_options.food_points[0]` = 2", "1..=1"],
    );
    refused(
        "metrics = [\"time_to_threshold\"]\n",
        &["`metric_options.thresholds` = []"],
    );
    refused(
        "metrics = [\"time_to_threshold\"]\n[metric_options]\nthresholds = [{ signal = \"speed\", below = 1.0 }]\n",
        &["`metric_options.thresholds[0].signal` = \"speed\""],
    );
    refused(
        "metrics = [\"time_to_threshold\"]\n[metric_options]\nthresholds = [{ signal = \"field_mass:XYZ\", below = 1.0 }]\n",
        &["field_mass:XYZ", "no pheromone `XYZ`"],
    );
    refused(
        "metrics = [\"time_to_threshold\"]\n[metric_options]\nthresholds = [{ signal = \"s\", below = 1.0, above = 2.0 }]\n",
        &["thresholds[0]", "exactly one of `below` and `above`"],
    );
    refused(
        "metrics = [\"s_mean\"]\n[metric_options]\nleader_role = \"queen\"\n",
        &["invalid sweep bad.toml: combination 0", "role \"queen\""],
    );
}
