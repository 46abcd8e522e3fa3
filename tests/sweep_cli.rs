//! `colcos sweep` as a user meets it: an interrupted sweep says so on its first line and exits non-zero
//! with how to resume; an axis with no effect is said to have none in summary.md (not named at its first
//! value); a bad axis is one line naming the sweep file, the axis, its key and value.
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

fn colcos() -> Command {
    Command::new(env!("CARGO_BIN_EXE_colcos"))
}

/// `colcos sweep <file> --out <out>`, more arguments to come.
fn sweep(file: &Path, out: &Path) -> Command {
    let mut c = colcos();
    c.arg("sweep").arg(file).arg("--out").arg(out);
    c
}

fn write_sweep(dir: &Path, name: &str, body: &str) -> PathBuf {
    let base = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/case2_alarm.toml");
    let path = dir.join(name);
    std::fs::write(&path, format!("scenario = \"{}\"\n{body}", base.display())).unwrap();
    path
}

/// A fresh directory holding the sweep file `name` (case II, `body`), the file, and the output
/// directory to give the sweep there.
fn new_sweep(name: &str, body: &str) -> (tempfile::TempDir, PathBuf, PathBuf) {
    let tmp = tempfile::tempdir().unwrap();
    let file = write_sweep(tmp.path(), name, body);
    let out = tmp.path().join("out");
    (tmp, file, out)
}

fn rows(out: &Path) -> usize {
    std::fs::read(out.join("results.csv"))
        .map(|b| b.iter().filter(|&&c| c == b'\n').count().saturating_sub(1))
        .unwrap_or(0)
}

#[test]
fn an_interrupted_sweep_says_so_and_exits_non_zero() {
    // 400 runs of 30 s on one thread: seconds of work, stopped after the first rows.
    let (_tmp, file, out) = new_sweep(
        "long.toml",
        "duration = 30.0\nseeds = 200\nmetrics = [\"s_mean\"]\n[[axes]]\nkey = \"robots[1].count\"\nvalues = [1, 3]\n",
    );
    let mut child = sweep(&file, &out)
        .args(["--threads", "1", "--quiet"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let started = Instant::now();
    while rows(&out) < 2 {
        assert!(child.try_wait().unwrap().is_none(), "the sweep ended first");
        assert!(started.elapsed() < Duration::from_secs(120), "no rows");
        std::thread::sleep(Duration::from_millis(5));
    }
    let status = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(status.success());
    let o = child.wait_with_output().unwrap();
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert_eq!(o.status.code(), Some(130), "{stdout}");
    let first = stdout.lines().next().unwrap_or_default();
    let done = rows(&out);
    assert!(done < 400, "{done}");
    for want in [
        "sweep long interrupted".to_string(),
        format!("{done} of 400 runs"),
        "--resume".to_string(),
        out.display().to_string(),
    ] {
        assert!(first.contains(&want), "first line {first:?} lacks {want:?}");
    }
    // The command it prints finishes the sweep.
    let o = sweep(&file, &out)
        .args(["--resume", "--quiet"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(rows(&out), 400);
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(stdout.starts_with("sweep long: 400 runs"), "{stdout}");
}

#[test]
fn an_axis_without_effect_is_said_to_have_none() {
    // The AGP follows the leader, refreshed every step: its evaporation never acts.
    let (_tmp, file, out) = new_sweep(
        "inert.toml",
        "duration = 5.0\nseeds = 2\nmetrics = [\"s_mean\", \"nn_distance\"]\n[[axes]]\nname = \"agp_e\"\nkeys = [\"pheromones[0].evaporation\", \"robots[0].emits[0].evaporation\"]\nrange = { from = 2.5, to = 40.0, steps = 3, scale = \"log\" }\n[[axes]]\nname = \"followers\"\nkey = \"robots[1].count\"\nvalues = [1, 3]\n",
    );
    let o = sweep(&file, &out).arg("--quiet").output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(
        stdout.contains("note: axis `agp_e` changed no metric"),
        "{stdout}"
    );
    let md = std::fs::read_to_string(out.join("summary.md")).unwrap();
    assert!(
        md.contains("**`agp_e`: no effect across this axis.**"),
        "{md}"
    );
    assert!(!md.contains("agp_e = 2.5"), "{md}");
    assert!(md.contains("followers = 1"), "{md}");
    assert!(
        !stdout.contains("`followers` changed no metric"),
        "{stdout}"
    );
}

#[test]
fn a_bad_axis_is_one_line_naming_the_file_axis_key_and_value() {
    let tmp = tempfile::tempdir().unwrap();
    for (body, want) in [
        (
            "[[axes]]\nkey = \"tracker.latencyy\"\nvalues = [0.1]\n",
            "axes[0] sets tracker.latencyy = 0.1",
        ),
        (
            "[[axes]]\nkey = \"robots[1]\"\nvalues = [3]\n",
            "axes[0] sets robots[1] = 3",
        ),
        (
            "[[axes]]\nkey = \"tracker.latency\"\nvalues = [0.1]\n[[axes]]\nname = \"lag\"\nkey = \"tracker.latency\"\nvalues = [0.2]\n",
            "axes[1] (lag) and axes[0] both set `tracker.latency`",
        ),
    ] {
        let file = write_sweep(
            tmp.path(),
            "bad.toml",
            &format!("duration = 1.0\nmetrics = [\"s_mean\"]\n{body}"),
        );
        let o = colcos()
            .arg("sweep")
            .arg(&file)
            .arg("--quiet")
            .output()
            .unwrap();
        assert!(!o.status.success());
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert_eq!(stderr.trim_end().lines().count(), 1, "{stderr}");
        assert!(stderr.contains(&file.display().to_string()), "{stderr}");
        assert!(stderr.contains(want), "{stderr}");
        assert!(
            !stderr.contains("RobotGroupSpec") && !stderr.contains("line 9"),
            "{stderr}"
        );
    }
}
