//! Running a sweep: the table does not depend on the number of threads, a table cut anywhere (a torn
//! last line) resumes to the uninterrupted table, and the metrics come out where they should.
use colcos_sweep::{Plan, SweepOptions, run_sweep};
use std::path::{Path, PathBuf};

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn tiny() -> Plan {
    Plan::from_file(repo().join("scenarios/sweeps/tiny.toml")).unwrap()
}

/// The table without its wall-time column.
fn table(dir: &Path) -> Vec<Vec<String>> {
    let mut r = csv::Reader::from_path(dir.join("results.csv")).unwrap();
    let header: Vec<String> = r.headers().unwrap().iter().map(String::from).collect();
    let wall = header.iter().position(|h| h == "wall_s").unwrap();
    let mut rows = vec![header];
    for rec in r.records() {
        rows.push(rec.unwrap().iter().map(String::from).collect());
    }
    for row in &mut rows {
        row.remove(wall);
    }
    rows
}

fn run(plan: &Plan, dir: &Path, threads: usize) {
    let opts = SweepOptions {
        threads: Some(threads),
        ..Default::default()
    };
    let report = run_sweep(plan, dir, opts).unwrap();
    assert!(!report.interrupted);
}

#[test]
fn one_and_two_threads_give_the_same_table() {
    let plan = tiny();
    let tmp = tempfile::tempdir().unwrap();
    let (a, b) = (tmp.path().join("a"), tmp.path().join("b"));
    run(&plan, &a, 1);
    run(&plan, &b, 2);
    let t = table(&a);
    assert_eq!(t.len(), 1 + 8);
    assert_eq!(t, table(&b));
    let ids: Vec<&str> = t[1..].iter().map(|r| r[0].as_str()).collect();
    assert_eq!(ids, ["0", "1", "2", "3", "4", "5", "6", "7"]);
    // Columns: ids, the two axes, the seed, the metrics (field_mass one per pheromone).
    assert_eq!(
        t[0],
        [
            "run_id",
            "combo",
            "follower_speed",
            "robots[1].count",
            "seed",
            "s_mean",
            "s_final",
            "s_halve_time",
            "nn_distance",
            "clusters",
            "area_covered",
            "collisions",
            "field_mass_AGP",
            "field_mass_ALP"
        ]
    );
    // Row 3: combination 1 (speed 0.05, 3 followers), seed 1.
    assert_eq!(&t[4][1..5], ["1", "0.05", "3", "1"]);
    // Seeds differ within a combination, and the AGP the leader emits has mass.
    assert_ne!(t[1][5], t[2][5]);
    let agp: f64 = t[1][12].parse().unwrap();
    assert!(agp > 0.0, "{agp}");
}

#[test]
fn a_table_cut_anywhere_resumes_to_the_uninterrupted_one() {
    let plan = tiny();
    let tmp = tempfile::tempdir().unwrap();
    let full_dir = tmp.path().join("full");
    run(&plan, &full_dir, 2);
    let full = std::fs::read(full_dir.join("results.csv")).unwrap();
    let expected = table(&full_dir);
    // Cut inside the header, at a line end, and inside rows.
    let header_len = full.iter().position(|&b| b == b'\n').unwrap() + 1;
    for cut in [
        5,
        header_len,
        header_len + 7,
        full.len() / 2,
        full.len() - 3,
    ] {
        let dir = tmp.path().join(format!("cut{cut}"));
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::copy(full_dir.join("plan.toml"), dir.join("plan.toml")).unwrap();
        std::fs::write(dir.join("results.csv"), &full[..cut]).unwrap();
        let opts = SweepOptions {
            threads: Some(2),
            resume: true,
            ..Default::default()
        };
        let report = run_sweep(&plan, &dir, opts).unwrap();
        assert_eq!(report.skipped + report.ran, 8, "cut at {cut}");
        assert_eq!(table(&dir), expected, "cut at {cut}");
    }
}

#[test]
fn a_finished_sweep_reruns_nothing_and_another_sweep_is_refused() {
    let plan = tiny();
    let tmp = tempfile::tempdir().unwrap();
    run(&plan, tmp.path(), 2);
    let again = run_sweep(&plan, tmp.path(), SweepOptions::default()).unwrap();
    assert_eq!((again.ran, again.skipped), (0, 8));
    let other = std::fs::read_to_string(repo().join("scenarios/sweeps/tiny.toml"))
        .unwrap()
        .replace("seeds = 2", "seeds = 3");
    let other =
        Plan::from_toml_str(&other, "other.toml", &repo().join("scenarios/sweeps")).unwrap();
    let e = run_sweep(&other, tmp.path(), SweepOptions::default()).unwrap_err();
    assert!(e.to_string().contains("different sweep"), "{e}");
    let e = run_sweep(
        &plan,
        &tmp.path().join("none"),
        SweepOptions {
            resume: true,
            ..Default::default()
        },
    )
    .unwrap_err();
    assert!(e.to_string().contains("nothing to resume"), "{e}");
}

#[test]
fn case_one_arrivals_end_a_run_and_count_food() {
    let text = r#"
scenario = "../case1_g3.toml"
duration = 60.0
seeds = [1, 2]
preload_steady_state = true
metrics = ["arrivals", "arrivals_food", "timeouts"]
[metric_options]
arrival_points = [
  [0.92, 0.75], [1.30, 0.725], [1.30, 0.625], [0.92, 0.56], [1.30, 0.535], [1.30, 0.435],
  [0.92, 0.37], [1.30, 0.345], [1.30, 0.245], [0.92, 0.18], [1.30, 0.155], [1.30, 0.055],
]
food_points = [3, 10]
"#;
    let plan = Plan::from_toml_str(text, "case1.toml", &repo().join("scenarios/sweeps")).unwrap();
    let rows = colcos_sweep::run_ids(&plan, &[0, 1]).unwrap();
    for r in rows {
        // G3 (all three pheromones) reaches food in every trial of the paper and of `colcos experiment`.
        assert_eq!(r.metrics, [Some(1.0), Some(1.0), Some(0.0)], "run {}", r.id);
    }
}

#[test]
fn a_table_being_written_is_not_opened_twice() {
    let plan = tiny();
    let tmp = tempfile::tempdir().unwrap();
    let open = colcos_sweep::ResultsTable::open(tmp.path(), &plan, false).unwrap();
    let e = run_sweep(&plan, tmp.path(), SweepOptions::default()).unwrap_err();
    assert!(e.to_string().contains("another sweep is writing"), "{e}");
    drop(open);
    let report = run_sweep(&plan, tmp.path(), SweepOptions::default()).unwrap();
    assert_eq!(report.ran, 8);
}

#[test]
fn traced_runs_give_the_same_row_and_the_poses_at_the_sample_times() {
    let plan = tiny().with_extra_metrics(&["mine".to_string()]).unwrap();
    assert_eq!(plan.columns[plan.columns.len() - 2..], ["mine", "wall_s"]);
    assert_ne!(plan.fingerprint, tiny().fingerprint);
    let scenario = plan.scenario(3).unwrap();
    let plain = colcos_sweep::run_one(&plan, 3, &scenario).unwrap();
    let (row, trace) = colcos_sweep::run_traced(&plan, 3, &scenario).unwrap();
    assert_eq!(row.metrics, plain.metrics);
    // 2 s sampled every 0.1 s from t = 0; 5 robots (3 followers).
    assert_eq!(trace.times.len(), 21);
    assert_eq!(trace.roles.len(), 5);
    assert_eq!(trace.positions.len(), 21 * 5 * 2);
    assert_eq!(row.fields(&plan)[plan.columns.len() - 2], "");
    assert!(tiny().with_extra_metrics(&["s_mean".to_string()]).is_err());
}

#[test]
fn the_finished_table_has_a_typed_parquet_copy_with_the_same_cells() {
    use parquet::file::reader::{FileReader, SerializedFileReader};
    use parquet::record::Field;
    let tmp = tempfile::tempdir().unwrap();
    run(&tiny(), tmp.path(), 2);
    let mut csv = csv::Reader::from_path(tmp.path().join("results.csv")).unwrap();
    let header: Vec<String> = csv.headers().unwrap().iter().map(String::from).collect();
    let rows: Vec<Vec<String>> = csv
        .records()
        .map(|r| r.unwrap().iter().map(String::from).collect())
        .collect();
    let file = std::fs::File::open(tmp.path().join("results.parquet")).unwrap();
    let reader = SerializedFileReader::new(file).unwrap();
    let got: Vec<_> = reader
        .get_row_iter(None)
        .unwrap()
        .map(|r| r.unwrap())
        .collect();
    assert_eq!(got.len(), rows.len());
    for (row, cells) in got.iter().zip(&rows) {
        let fields: Vec<_> = row.get_column_iter().collect();
        assert_eq!(fields.len(), header.len());
        for ((name, field), (column, cell)) in fields.iter().zip(header.iter().zip(cells)) {
            assert_eq!(*name, column);
            match field {
                Field::Long(v) => assert_eq!(v.to_string(), *cell, "{column}"),
                Field::Double(v) => assert_eq!(*v, cell.parse::<f64>().unwrap(), "{column}"),
                Field::Str(v) => assert_eq!(v, cell, "{column}"),
                Field::Null => assert!(cell.is_empty(), "{column}"),
                other => panic!("{column}: unexpected {other:?}"),
            }
        }
    }
    // The run ids and seeds are integers, the metrics numbers.
    let first: Vec<_> = got[0].get_column_iter().collect();
    assert!(matches!(first[0].1, Field::Long(0)));
    let s_mean = header.iter().position(|h| h == "s_mean").unwrap();
    assert!(matches!(first[s_mean].1, Field::Double(_)));
}
