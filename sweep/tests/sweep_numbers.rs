//! The numbers a user reads in the table are the ones they would write: log-range values as 5 and 20
//! (not 5.000000000000001 and 19.999999999999996), times as 2.6 s (not the f32 2.5999999046325684).
use colcos_sweep::Plan;
use colcos_sweep::runner::value_text;
use std::path::Path;

fn sweeps_dir() -> &'static Path {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../scenarios/sweeps"))
}

#[test]
fn log_range_values_are_written_as_round_numbers() {
    let text = r#"
scenario = "../case2_alarm.toml"
duration = 1.0
metrics = ["s_mean"]
[[axes]]
key = "pheromones[1].evaporation"
range = { from = 2.5, to = 40.0, steps = 5, scale = "log" }
[[axes]]
key = "robots[1].params.speed"
range = { from = 0.02, to = 0.08, steps = 4 }
"#;
    let plan = Plan::from_toml_str(text, "numbers.toml", sweeps_dir()).unwrap();
    let column = |i: usize| {
        let mut v: Vec<String> = plan.combos.iter().map(|c| value_text(&c[i])).collect();
        v.dedup();
        v
    };
    assert_eq!(column(0), ["2.5", "5", "10", "20", "40"]);
    let mut speeds = column(1);
    speeds.sort();
    speeds.dedup();
    assert_eq!(speeds, ["0.02", "0.04", "0.06", "0.08"]);
    // The values set in the scenario are the values in the table.
    assert_eq!(
        plan.scenario(4).unwrap().spec.pheromones[1].evaporation,
        Some(5.0)
    );
}

#[test]
fn times_and_f32_metrics_are_written_as_the_simulator_has_them() {
    let text = r#"
scenario = "../case2_alarm.toml"
duration = 20.0
seeds = 4
metrics = ["s_final", "s_halve_time", "time_to_threshold"]
[metric_options]
thresholds = [{ signal = "nn_distance", below = 0.25 }]
"#;
    let plan = Plan::from_toml_str(text, "numbers.toml", sweeps_dir()).unwrap();
    let rows = colcos_sweep::run_ids(&plan, &[0, 1, 2, 3]).unwrap();
    let mut times = 0;
    for row in &rows {
        let cells = row.fields(&plan);
        let cell = |name: &str| &cells[plan.columns.iter().position(|c| c == name).unwrap()];
        // Sample times are multiples of 0.1 s: at most one decimal.
        for name in ["s_halve_time", "time_to_nn_distance_below_0.25"] {
            let c = cell(name);
            if c.is_empty() {
                continue;
            }
            times += 1;
            let decimals = c.split_once('.').map_or(0, |(_, d)| d.len());
            assert!(decimals <= 1, "{name} = {c}");
        }
        // An f32 distance: its own shortest digits (at most 9 significant), not its widened f64's 17.
        let s = cell("s_final");
        let digits = s.chars().filter(char::is_ascii_digit).count();
        assert!(digits <= 10, "s_final = {s}");
    }
    assert!(times >= 4, "too few times to check: {times}");
}
