//! The command line's report on stdout.
use std::process::{Command, Stdio};

/// `colcos behaviours | grep -q wander` closes the pipe early: the report's writer must not panic.
#[test]
fn a_reader_that_went_away_is_not_an_error() {
    let (reader, writer) = std::io::pipe().expect("a pipe");
    drop(reader); // every write to the pipe now fails with EPIPE
    let out = Command::new(env!("CARGO_BIN_EXE_colcos"))
        .arg("behaviours")
        .stdout(Stdio::from(writer))
        .stderr(Stdio::piped())
        .output()
        .expect("colcos runs");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "exit {:?}: {stderr}", out.status);
    assert!(!stderr.contains("panicked"), "{stderr}");
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
