//! `colcos bridge` against a tracker that is not there: the address and the reason are said once,
//! with plain sentences (no Rust debug forms), and the run fails instead of reporting success.
mod common;
use common::{colcos, failed};

fn dead_port() -> u16 {
    let l = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    l.local_addr().unwrap().port()
}

#[test]
fn a_bridge_whose_tracker_is_not_there_says_so_once_and_fails() {
    let dir = tempfile::tempdir().unwrap();
    let tracker = format!("swarmcon://127.0.0.1:{}", dead_port());
    let robots = format!("udp://127.0.0.1:{}", dead_port());
    let scenario = concat!(env!("CARGO_MANIFEST_DIR"), "/scenarios/case2_alarm.toml");
    let out = colcos(&[
        "bridge",
        scenario,
        "--tracker",
        &tracker,
        "--robots",
        &robots,
    ])
    .args(["--duration", "2", "--quiet", "--out"])
    .arg(dir.path())
    .output()
    .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{stderr}");
    let port = tracker.trim_start_matches("swarmcon://");
    assert_eq!(
        stderr.matches("no poses from the tracker at").count(),
        1,
        "{stderr}"
    );
    assert!(
        stderr.contains(&format!("{port}: Connection refused")),
        "{stderr}"
    );
    assert!(
        stderr.contains(&format!(
            "error: no pose arrived from the tracker {tracker}"
        )),
        "{stderr}"
    );
    for debug_form in ["Shutdown(", "LinkError(", "TrackerSilent {", "PoseStale {"] {
        assert!(!stderr.contains(debug_form), "{debug_form} in {stderr}");
    }
    let summary: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["interrupted"], false);
    assert_eq!(summary["pose_blocks"], 0);
    assert!(
        summary["tracker_problem"]
            .as_str()
            .is_some_and(|p| p.contains("refused")),
        "{summary}"
    );
}

/// `colcos check` refuses what the bridge would refuse as it starts: a `[rig] screen_calibration`
/// that does not exist, named by its key.
#[test]
fn check_refuses_a_missing_screen_calibration_naming_the_key() {
    let dir = tempfile::tempdir().unwrap();
    let base = concat!(env!("CARGO_MANIFEST_DIR"), "/scenarios/case2_alarm.toml");
    let text = std::fs::read_to_string(base).unwrap();
    let text = if text.contains("[rig]") {
        text.replace(
            "[rig]",
            "[rig]\nscreen_calibration = \"nowhere/screen.json\"",
        )
    } else {
        format!("{text}\n[rig]\nscreen_calibration = \"nowhere/screen.json\"\n")
    };
    let path = common::write(dir.path(), "s.toml", &text);
    let stderr = failed(colcos(&["check"]).arg(&path));
    assert!(stderr.contains("rig.screen_calibration"), "{stderr}");
    assert!(stderr.contains("nowhere/screen.json"), "{stderr}");
}

/// `colcos calibrate --out calib/screen.json` makes `calib/` before it measures anything, so that a
/// measurement is never lost to a missing folder (here the tracker is not there, and the folder is
/// made all the same).
#[test]
fn calibrate_makes_its_output_folder_before_measuring() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("calib").join("screen.json");
    let scenario = concat!(env!("CARGO_MANIFEST_DIR"), "/scenarios/case2_alarm.toml");
    let tracker = format!("swarmcon://127.0.0.1:{}", dead_port());
    let stderr = failed(
        colcos(&["calibrate", "screen", scenario, "--tracker", &tracker])
            .args(["--frames", "127.0.0.1:0", "--out"])
            .arg(&out),
    );
    assert!(stderr.contains("--tracker"), "{stderr}");
    assert!(dir.path().join("calib").is_dir());
}
