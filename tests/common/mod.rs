//! Running the `colcos` binary, for the command-line tests (each uses its part).
#![allow(dead_code)]
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// `colcos` with `args`, run from the repository's root (where `scenarios/` is).
pub fn colcos<S: AsRef<std::ffi::OsStr>>(args: &[S]) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_colcos"));
    c.args(args).current_dir(env!("CARGO_MANIFEST_DIR"));
    c
}

/// What `command` printed, which must have succeeded (else its stderr is shown).
#[track_caller]
pub fn succeeded(command: &mut Command) -> Output {
    let out = command.output().expect("colcos runs");
    assert!(
        out.status.success(),
        "{command:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// The stderr of `command`, which must have failed.
#[track_caller]
pub fn failed(command: &mut Command) -> String {
    let out = command.output().expect("colcos runs");
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(!out.status.success(), "{command:?} succeeded: {stderr}");
    stderr
}

/// Writes `text` to the file `name` in `dir`; its path.
pub fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}
