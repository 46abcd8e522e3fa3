//! `colcos bridge` against a tracker that is not there: the address and the reason are said once,
//! with plain sentences (no Rust debug forms), and the run fails instead of reporting success.
use std::process::Command;

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
    let out = Command::new(env!("CARGO_BIN_EXE_colcos"))
        .args([
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
