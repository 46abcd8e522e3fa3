//! The twin plant with hidden per-robot truths (`PlantOptions::twin_truth`, Python `truth=`): the
//! twin's robots drive with their own wheel scales while the host assumes the nominal ones, so the
//! host sees its agents cover less ground than it commanded; a bad truth file is refused by name.
mod common;

use colcos_env::{Actions, VecEnv};
use colcos_plant::{LiveEnv, PlantKind, PlantOptions};
use common::{config, twin_at_rest};

/// Mean distance (m) the host sees its agents cover in 40 steps at half speed ahead.
fn distance_seen(truth: Option<std::path::PathBuf>) -> f32 {
    let (mut env, n) = twin_at_rest(|opts| opts.twin_truth = truth, 10);
    let agents = env.spec().agent_robots.clone();
    let start: Vec<_> = env.host().tracked().to_vec();
    for _ in 0..40 {
        env.step(Actions::Continuous(&vec![0.5; 2 * n])).unwrap();
    }
    let end = env.host().tracked();
    agents
        .iter()
        .map(|&i| (end[i].pose.pos - start[i].pose.pos).length())
        .sum::<f32>()
        / agents.len() as f32
}

#[test]
fn a_twin_with_slow_wheels_is_seen_to_cover_less_ground() {
    let dir = tempfile::tempdir().unwrap();
    let agents = VecEnv::new(&config()).unwrap().spec().agent_robots.clone();
    let truth: String = agents
        .iter()
        .map(|i| format!("[[robot]]\nindex = {i}\nwheel_scale = [0.4, 0.4]\n"))
        .collect();
    let path = dir.path().join("truth.toml");
    std::fs::write(&path, truth).unwrap();
    let nominal = distance_seen(None);
    let slow = distance_seen(Some(path));
    // Wheels at 0.4 of the command: 0.4 of the distance, give or take the walls and the start.
    assert!(
        slow < 0.6 * nominal && slow > 0.2 * nominal,
        "agents covered {slow} m on the slow twin, {nominal} m on the nominal one"
    );

    let bad = dir.path().join("bad.toml");
    std::fs::write(&bad, "[[robot]]\nindex = 0\nwheel_scale = [0.0, 1.0]\n").unwrap();
    let mut opts = PlantOptions::new(PlantKind::Twin);
    opts.twin_truth = Some(bad);
    let err = LiveEnv::new(&config(), &opts).err().unwrap().to_string();
    assert!(
        err.contains("truth") && err.contains("wheel_scale"),
        "{err}"
    );
}
