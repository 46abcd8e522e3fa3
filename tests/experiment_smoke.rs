//! `colcos experiment all` through the library with a few short trials: every file is written and the
//! numbers have the right shape.
use colcos::experiment::{Options, Which, run};
use colcos_testkit::threads::on_threads;

#[test]
fn a_few_trials_of_each_case_write_every_file() {
    let dir = tempfile::tempdir().unwrap();
    let mut opts = Options::new(Which::All, dir.path());
    opts.trials = 2;
    opts.runs = 1;
    let report = run(&opts).unwrap();
    for f in [
        "case1/arrivals.csv",
        "case1/trials.csv",
        "case1/fig5_arrivals.png",
        "case1/fig6_g3_trajectories.png",
        "case2/s_t.csv",
        "case2/fig8_s_t.png",
        "case2/fig7_snapshots.png",
        "case2/trajectories.png",
        "summary.json",
        "summary.md",
    ] {
        let p = dir.path().join(f);
        assert!(
            p.is_file() && std::fs::metadata(&p).unwrap().len() > 0,
            "{f} missing"
        );
    }
    // Pictures decode at a sensible size.
    let img = image::open(dir.path().join("case1/fig5_arrivals.png")).unwrap();
    assert!(img.width() >= 800 && img.height() >= 600);

    let r1 = report.case1.as_ref().unwrap();
    assert_eq!(r1.groups.len(), 3);
    let ends = r1.config.layout.ends.len();
    assert!(ends >= 10, "at least ten end points");
    for g in &r1.groups {
        assert_eq!(g.counts.per_point.len(), ends);
        assert_eq!(g.counts.trials(), 2);
    }
    let csv = std::fs::read_to_string(dir.path().join("case1/arrivals.csv")).unwrap();
    assert_eq!(csv.lines().count(), 1 + 3 * (ends + 1));

    let r2 = report.case2.as_ref().unwrap();
    assert_eq!(r2.runs.len(), 1);
    let run0 = &r2.runs[0];
    assert_eq!(run0.times.len(), run0.s.len());
    assert!(run0.s.iter().all(|s| s.is_finite() && *s >= 0.0));
    assert!(!run0.phases.is_empty());

    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("summary.json")).unwrap())
            .unwrap();
    let g = &json["case1"]["groups"][0];
    assert_eq!(g["arrivals"].as_array().unwrap().len(), ends);
    assert!(g["timeouts"].is_u64());
    assert_eq!(g["available_food"], serde_json::json!([3, 10]));
    assert_eq!(
        json["case2"]["runs"][0]["s"].as_array().unwrap().len(),
        run0.s.len()
    );
    assert!(json["case2"]["runs"][0]["phase_boundaries"].is_array());
}

#[test]
fn results_do_not_depend_on_the_thread_count() {
    let dir = tempfile::tempdir().unwrap();
    let mut opts = Options::new(Which::Case1, dir.path());
    opts.trials = 3;
    let a = run(&opts).unwrap().case1.unwrap();
    let b = on_threads(1, || run(&opts).unwrap().case1.unwrap());
    for (x, y) in a.groups.iter().zip(&b.groups) {
        assert_eq!(x.counts, y.counts);
    }
}
