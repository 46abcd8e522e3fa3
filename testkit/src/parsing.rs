//! Support for the tests of scenario parsing and validation, which keep their TOML text: a minimal
//! valid scenario to edit into bad ones, and assertions that the bad ones are refused, naming the key.
use colcos_sim::scenario::Scenario;
use std::path::Path;

/// A minimal valid scenario file: 1 s, a grid pheromone `trail` (blue, 10 s evaporation) and three
/// robots that avoid each other, last in the file (so that text appended goes into their table).
pub const TRAIL_AVOIDERS: &str = r#"
duration = 1.0
[[pheromones]]
name = "trail"
colour = [0, 0, 255]
evaporation = 10.0
[[robots]]
count = 3
behaviour = "avoid"
"#;

/// The error parsing and validating `text` gives (relative paths from `dir`); panics, showing the
/// text, when it is accepted.
#[track_caller]
pub fn refusal_in(text: &str, dir: &Path) -> String {
    match Scenario::from_toml_str(text, dir) {
        Ok(_) => panic!("scenario was accepted:\n{text}"),
        Err(e) => e.to_string(),
    }
}

/// Asserts that `text` is refused (relative paths from `dir`) with an error that mentions every one
/// of `needles`.
#[track_caller]
pub fn assert_refused_in(text: &str, dir: &Path, needles: &[&str]) {
    let msg = refusal_in(text, dir);
    for n in needles {
        assert!(msg.contains(n), "error {msg:?} does not mention {n:?}");
    }
}

/// [`assert_refused_in`] from the working directory.
#[track_caller]
pub fn assert_refused(text: &str, needles: &[&str]) {
    assert_refused_in(text, Path::new("."), needles);
}

/// [`assert_refused`] for every case: a scenario text, and what its error must mention. A failure
/// names the case by its place in `cases` and its needles.
#[track_caller]
pub fn assert_all_refused(cases: &[(String, &[&str])]) {
    for (k, (text, needles)) in cases.iter().enumerate() {
        let msg = refusal_in(text, Path::new("."));
        for n in *needles {
            assert!(
                msg.contains(n),
                "case {k} {needles:?}: error {msg:?} does not mention {n:?}"
            );
        }
    }
}
