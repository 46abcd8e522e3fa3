//! Bad input on the command line, or in the scenario it names, is a clear error at once: exit status
//! non-zero, the key or flag named, no panic. And what `colcos check` accepts, `colcos run` runs.
use std::path::Path;
use std::process::{Command, Output};

const GOOD: &str = r#"
duration = 0.1
[output]
gif_interval = 0.0
[[pheromones]]
name = "trail"
colour = [0, 0, 255]
evaporation = 10.0
[[robots]]
count = 3
behaviour = "avoid"
"#;

fn colcos(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_colcos"))
        .args(args)
        .output()
        .expect("colcos runs")
}

#[track_caller]
fn assert_fails(args: &[&str], needles: &[&str]) {
    let out = colcos(args);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{args:?} succeeded: {stderr}");
    assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
    for n in needles {
        assert!(
            stderr.contains(n),
            "{args:?}: {stderr:?} does not mention {n:?}"
        );
    }
}

fn write(dir: &Path, name: &str, text: &str) -> String {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path.to_str().unwrap().to_owned()
}

#[test]
fn check_refuses_what_run_would_refuse_when_building() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let out = out.to_str().unwrap();
    let image = write(
        dir.path(),
        "image.toml",
        &GOOD.replace(
            "evaporation = 10.0",
            "evaporation = 10.0\nmaps = [{ image = \"missing.png\", rate = 1 }]",
        ),
    );
    let crowded = write(
        dir.path(),
        "crowded.toml",
        &GOOD.replace("count = 3", "count = 25\nregion = [0.5, 0.5, 0.7, 0.7]"),
    );
    for (file, key) in [
        (&image, "pheromones[0].maps[0].image"),
        (&crowded, "robots[0].placement"),
    ] {
        assert_fails(&["check", file], &[key]);
        assert_fails(&["run", file, "--quiet", "--out", out], &[key]);
    }
}

#[test]
fn a_checked_scenario_runs() {
    let dir = tempfile::tempdir().unwrap();
    let file = write(dir.path(), "good.toml", GOOD);
    assert!(colcos(&["check", &file]).status.success());
    let out = dir.path().join("out");
    let run = colcos(&["run", &file, "--quiet", "--out", out.to_str().unwrap()]);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
}

fn strs(args: &[String]) -> Vec<&str> {
    args.iter().map(String::as_str).collect()
}

#[test]
fn run_arguments_are_bounded() {
    let dir = tempfile::tempdir().unwrap();
    let file = write(dir.path(), "good.toml", GOOD);
    let out = dir.path().join("out");
    let out = out.to_str().unwrap();
    let run = |extra: &[&'static str]| -> Vec<String> {
        let base = ["run", file.as_str(), "--quiet", "--out", out];
        base.iter().chain(extra).map(|a| a.to_string()).collect()
    };
    assert_fails(&strs(&run(&["--threads", "0"])), &["--threads", "1..=1024"]);
    assert_fails(
        &strs(&run(&["--threads", "5000"])),
        &["--threads", "1..=1024"],
    );
    assert_fails(&strs(&run(&["--duration=-1"])), &["duration", "-1"]);
    assert_fails(&strs(&run(&["--duration", "NaN"])), &["duration", "NaN"]);
    assert_fails(&strs(&run(&["--duration", "inf"])), &["duration"]);
    assert!(!Path::new(out).join("trajectory.csv").exists());
}
