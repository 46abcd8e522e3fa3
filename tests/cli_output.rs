//! The command line's report on stdout.
use std::process::{Command, Stdio};

/// Runs `colcos ARGS` with stdout into a pipe whose reader is already gone, as in
/// `colcos ... | grep -q x` after grep's first match: the command must still succeed.
fn assert_survives_closed_pipe(args: &[&str]) {
    let (reader, writer) = std::io::pipe().expect("a pipe");
    drop(reader); // every write to the pipe now fails with EPIPE
    let out = Command::new(env!("CARGO_BIN_EXE_colcos"))
        .args(args)
        .stdout(Stdio::from(writer))
        .stderr(Stdio::piped())
        .output()
        .expect("colcos runs");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        out.status.success(),
        "{args:?}: exit {:?}: {stderr}",
        out.status
    );
    assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
}

#[test]
fn a_reader_that_went_away_is_not_an_error() {
    assert_survives_closed_pipe(&["behaviours"]);
    assert_survives_closed_pipe(&["check", "scenarios/three_trails.toml"]);
}

/// The experiment's report (a table of claims and the files written) goes through the same writer.
#[test]
fn the_experiment_report_survives_a_closed_pipe() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let out = dir.path().to_str().expect("a UTF-8 path");
    assert_survives_closed_pipe(&[
        "experiment",
        "case2",
        "--runs",
        "1",
        "--quiet",
        "--out",
        out,
    ]);
}

#[test]
fn the_report_reaches_a_reader() {
    let out = Command::new(env!("CARGO_BIN_EXE_colcos"))
        .arg("behaviours")
        .output()
        .expect("colcos runs");
    assert!(out.status.success());
    assert!(String::from_utf8_lossy(&out.stdout).contains("wander"));
}
