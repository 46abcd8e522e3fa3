//! `colcos rig check`: behaviours that drive into the walls are refused with the limit named; the
//! paper's case-II behaviours pass.
use std::process::Command;

fn rig_check(scenario: &std::path::Path) -> (bool, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_colcos"))
        .args(["rig", "check"])
        .arg(scenario)
        .args(["--episodes", "1", "--seconds", "2", "--max-overruns", "0.5"])
        .output()
        .unwrap();
    let text =
        String::from_utf8_lossy(&out.stdout).to_string() + &String::from_utf8_lossy(&out.stderr);
    (out.status.success(), text)
}

#[test]
fn wall_seeking_behaviours_are_refused_and_case_two_passes() {
    let dir = tempfile::tempdir().unwrap();
    let walls = dir.path().join("walls.toml");
    std::fs::write(
        &walls,
        "duration = 10.0\n[screen]\nresolution = [640, 640]\nsize = [0.3, 0.3]\n\
         [[robots]]\ncount = 3\nbehaviour = \"wander\"\nparams = { speed = 0.3 }\n",
    )
    .unwrap();
    let (ok, text) = rig_check(&walls);
    assert!(
        !ok && text.contains("pre-flight refused: walled = "),
        "{text}"
    );
    let case2 = concat!(env!("CARGO_MANIFEST_DIR"), "/scenarios/case2_alarm.toml");
    let (ok, text) = rig_check(std::path::Path::new(case2));
    assert!(ok && text.contains("pre-flight passed"), "{text}");
}

/// Every scenario shipped under `scenarios/` may drive a rig: its behaviours pass the pre-flight (a
/// short episode each; `colcos rig check` with its defaults runs three of 20 s).
#[test]
fn every_shipped_scenario_passes_the_pre_flight() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/scenarios");
    let mut failed = Vec::new();
    let mut paths: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    paths.sort();
    assert!(paths.len() >= 10, "{paths:?}");
    for path in paths {
        let (ok, text) = rig_check(&path);
        if !ok {
            failed.push(format!("{}: {text}", path.display()));
        }
    }
    assert!(failed.is_empty(), "{failed:#?}");
}
