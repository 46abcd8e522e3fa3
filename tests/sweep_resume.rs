//! `colcos sweep` killed with SIGKILL and resumed: the harness watches the results table and kills the
//! child as soon as it holds K rows (K = 0 kills it right after the header), then resumes it, once or
//! several times; the final table equals an uninterrupted sweep's (wall times aside), with no run twice.
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

fn colcos() -> Command {
    Command::new(env!("CARGO_BIN_EXE_colcos"))
}

/// A case-II sweep of 24 runs long enough (30 s simulated each, ~10 ms of wall time) for the harness to
/// catch it midway.
fn sweep_file(dir: &Path) -> PathBuf {
    let repo = Path::new(env!("CARGO_MANIFEST_DIR"));
    let base = repo.join("scenarios/case2_alarm.toml");
    let text = format!(
        r#"scenario = "{}"
duration = 30.0
seeds = 4
metrics = ["s_mean", "s_final", "nn_distance", "collisions", "area_covered"]
[[axes]]
key = "robots[1].count"
values = [1, 2, 3]
[[axes]]
name = "agp_e"
keys = ["pheromones[0].evaporation", "robots[0].emits[0].evaporation"]
values = [5.0, 10.0]
"#,
        base.display()
    );
    let path = dir.join("resume.toml");
    std::fs::write(&path, text).unwrap();
    path
}

fn sweep(file: &Path, out: &Path, extra: &[&str]) -> Command {
    let mut c = colcos();
    c.arg("sweep")
        .arg(file)
        .arg("--out")
        .arg(out)
        .args(["--threads", "1", "--quiet"])
        .args(extra)
        .stdout(Stdio::null())
        .stderr(Stdio::piped());
    c
}

fn complete_rows(out: &Path) -> usize {
    std::fs::read(out.join("results.csv"))
        .map(|b| b.iter().filter(|&&c| c == b'\n').count().saturating_sub(1))
        .unwrap_or(0)
}

/// Starts the sweep and kills it with SIGKILL once the table holds `k` rows (or it ended first).
fn run_and_kill_after(file: &Path, out: &Path, k: usize) {
    let mut child = sweep(file, out, &[]).spawn().unwrap();
    let started = Instant::now();
    loop {
        if child.try_wait().unwrap().is_some() {
            return;
        }
        // The header line complete (the file exists a moment before it is written).
        let header = std::fs::read(out.join("results.csv")).is_ok_and(|b| b.contains(&b'\n'));
        if header && complete_rows(out) >= k {
            child.kill().unwrap();
            child.wait().unwrap();
            return;
        }
        assert!(
            started.elapsed() < Duration::from_secs(120),
            "the sweep hangs"
        );
        std::thread::yield_now();
    }
}

/// The table's rows without the wall-time column, and the run ids in file order.
fn table(out: &Path) -> (Vec<Vec<String>>, Vec<u64>) {
    let mut r = csv::Reader::from_path(out.join("results.csv")).unwrap();
    let header: Vec<String> = r.headers().unwrap().iter().map(String::from).collect();
    let wall = header.iter().position(|h| h == "wall_s").unwrap();
    let mut rows = vec![header];
    let mut ids = Vec::new();
    for rec in r.records() {
        let mut row: Vec<String> = rec.unwrap().iter().map(String::from).collect();
        ids.push(row[0].parse().unwrap());
        row.remove(wall);
        rows.push(row);
    }
    (rows, ids)
}

fn finish(file: &Path, out: &Path) {
    let o = sweep(file, out, &["--resume"]).output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

#[test]
fn killed_and_resumed_sweeps_give_the_uninterrupted_table() {
    let tmp = tempfile::tempdir().unwrap();
    let file = sweep_file(tmp.path());
    let whole = tmp.path().join("whole");
    let o = sweep(&file, &whole, &[]).output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let (expected, ids) = table(&whole);
    assert_eq!(ids, (0..24).collect::<Vec<u64>>());

    // One kill at each of several moments, then one sweep killed three times.
    let plans: [&[usize]; 5] = [&[0], &[1], &[7], &[20], &[3, 9, 16]];
    let mut killed_midway = 0;
    for (n, kills) in plans.iter().enumerate() {
        let out = tmp.path().join(format!("killed{n}"));
        for &k in kills.iter() {
            run_and_kill_after(&file, &out, k);
            let rows = complete_rows(&out);
            if rows < 24 {
                killed_midway += 1;
            }
            let (_, ids) = table(&out);
            let mut unique = ids.clone();
            unique.sort();
            unique.dedup();
            assert_eq!(
                unique.len(),
                ids.len(),
                "a run written twice after kills {kills:?}"
            );
        }
        finish(&file, &out);
        let (got, ids) = table(&out);
        assert_eq!(ids, (0..24).collect::<Vec<u64>>(), "kills {kills:?}");
        assert_eq!(got, expected, "kills {kills:?}");
    }
    // The harness must have caught most sweeps before their end, or it tested nothing.
    assert!(
        killed_midway >= 4,
        "only {killed_midway} kills landed before the end"
    );
}

#[test]
fn bad_sweeps_fail_before_running_and_name_the_key() {
    let tmp = tempfile::tempdir().unwrap();
    let repo = Path::new(env!("CARGO_MANIFEST_DIR"));
    let text = format!(
        "scenario = \"{}\"\nmetrics = [\"s_mean\"]\n[[axes]]\nkey = \"robots[1].count\"\nvalues = [1, 3, -2]\n",
        repo.join("scenarios/case2_alarm.toml").display()
    );
    let file = tmp.path().join("bad.toml");
    std::fs::write(&file, text).unwrap();
    let out = tmp.path().join("out");
    let o = sweep(&file, &out, &[]).output().unwrap();
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("combination 2") && err.contains("robots[1].count = -2"),
        "{err}"
    );
    assert!(
        !out.join("results.csv").exists(),
        "a bad sweep must not start a table"
    );
}
