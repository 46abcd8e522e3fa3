//! `colcos rig check`: behaviours that drive into the walls are refused with the limit named; the
//! paper's case-II behaviours pass. `colcos rig excite` refuses, before anything moves and with the
//! reason, an excitation the arena and its shield cannot hold; `colcos rig identify` refuses a log
//! of another scenario.
mod common;

/// Runs `colcos` with `args`: whether it succeeded, and its stdout then stderr.
fn colcos(args: &[&str]) -> (bool, String) {
    let out = common::colcos(args).output().unwrap();
    let text =
        String::from_utf8_lossy(&out.stdout).to_string() + &String::from_utf8_lossy(&out.stderr);
    (out.status.success(), text)
}

/// `colcos rig check` of `scenario`, one short episode: 4 s, so that a lone robot's one approach to
/// a wall (up to 5 walled ticks on a loaded machine) stays under the 5 % limit of its robot-ticks.
fn rig_check(scenario: &std::path::Path) -> (bool, String) {
    let path = scenario.to_str().unwrap();
    colcos(&[
        "rig",
        "check",
        path,
        "--episodes",
        "1",
        "--seconds",
        "4",
        "--max-overruns",
        "0.5",
    ])
}

#[test]
fn wall_seeking_behaviours_are_refused_and_case_two_passes() {
    let dir = tempfile::tempdir().unwrap();
    let walls = common::write(
        dir.path(),
        "walls.toml",
        "duration = 10.0\n[screen]\nresolution = [640, 640]\nsize = [0.3, 0.3]\n\
         [[robots]]\ncount = 3\nbehaviour = \"wander\"\nparams = { speed = 0.3 }\n",
    );
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
    let mut failed = Vec::new();
    let paths = colcos_testkit::scenarios::shipped(&["scenarios"]);
    assert!(paths.len() >= 10, "{paths:?}");
    for path in paths {
        let (ok, text) = rig_check(&path);
        if !ok {
            failed.push(format!("{}: {text}", path.display()));
        }
    }
    assert!(failed.is_empty(), "{failed:#?}");
}

#[test]
fn an_excitation_that_would_leave_the_arena_is_refused_with_the_reason() {
    let dir = tempfile::tempdir().unwrap();
    let base = "name = \"lab\"\nduration = 10.0\n[[robots]]\ncount = 2\nbehaviour = \"wander\"\n";
    // No tracker or radio is there: the refusal must come before either is opened.
    let excite = |name: &str, extra: &str| {
        let path = common::write(dir.path(), name, &format!("{base}{extra}"));
        let out = dir.path().join("out");
        colcos(&[
            "rig",
            "excite",
            path.to_str().unwrap(),
            "--tracker",
            "swarmcon://127.0.0.1:9",
            "--robots",
            "udp://127.0.0.1:9",
            "--seconds",
            "1",
            "--out",
            out.to_str().unwrap(),
        ])
    };
    let (ok, text) = excite("margin.toml", "[rig]\nshield = { margin = 0.01 }\n");
    assert!(
        !ok && text
            .contains("refused: [rig] shield.margin = 0.01 m is less than the robot's radius"),
        "{text}"
    );
    let (ok, text) = excite(
        "stop.toml",
        "[robot]\nmotor_lag = 0.4\n[rig]\nshield = { horizon = 0.0 }\n",
    );
    assert!(!ok && text.contains("while it stops"), "{text}");
    let (ok, text) = excite(
        "small.toml",
        "[screen]\nresolution = [100, 100]\nsize = [0.15, 0.15]\n",
    );
    assert!(!ok && text.contains("inside the shield's walls"), "{text}");
    assert!(!dir.path().join("out").join("rig.mcap").exists());

    // A log of the identify fixture's scenario, identified against another one.
    let fixture = concat!(env!("CARGO_MANIFEST_DIR"), "/bridge/tests/data/identify");
    let scenario = std::fs::read_to_string(format!("{fixture}/scenario.toml")).unwrap();
    let other = scenario.replace("name = \"identify\"", "name = \"other\"");
    let other = common::write(dir.path(), "other.toml", &other);
    let fit = dir.path().join("fit.toml");
    let (ok, text) = colcos(&[
        "rig",
        "identify",
        &format!("{fixture}/rig.mcap"),
        "--scenario",
        other.to_str().unwrap(),
        "--out",
        fit.to_str().unwrap(),
    ]);
    assert!(
        !ok && text
            .contains("the rig log is of scenario \"identify\" with 3 robots, not \"other\""),
        "{text}"
    );
    assert!(!fit.exists());
}
