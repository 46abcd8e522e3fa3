//! Golden outputs: the default scenario and both case studies, run by the `colcos` binary with a fixed
//! seed, write exactly these bytes. A refactoring that changes any of them changes behaviour.
//! `COLCOS_GOLDEN_PRINT=1 cargo test --release --test golden -- --nocapture` prints the current hashes.
mod common;
use common::{colcos, succeeded};
use std::path::Path;

/// FNV-1a, 64-bit: stable across Rust versions (std's hasher is not).
fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ b as u64).wrapping_mul(0x0100_0000_01b3)
    })
}

/// Every file under `dir` that a run writes deterministically, with its hash, sorted by path.
fn hashes(dir: &Path) -> Vec<(String, u64)> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for entry in std::fs::read_dir(&d).unwrap() {
            let path = entry.unwrap().path();
            let name = path
                .strip_prefix(dir)
                .unwrap()
                .to_string_lossy()
                .replace('\\', "/");
            if path.is_dir() {
                stack.push(path);
            } else if !name.ends_with(".json") && !name.ends_with(".md") {
                // summary.json holds wall-clock times; report.md quotes them.
                out.push((name, fnv1a(&std::fs::read(&path).unwrap())));
            }
        }
    }
    out.sort();
    out
}

/// Runs `colcos args --out <out>`, and hashes what it wrote.
fn run_into(args: &[&str], out: &Path) -> Vec<(String, u64)> {
    succeeded(colcos(args).arg("--out").arg(out));
    hashes(out)
}

fn check(label: &str, got: Vec<(String, u64)>, want: &[(&str, u64)]) {
    if std::env::var("COLCOS_GOLDEN_PRINT").is_ok_and(|v| v == "1") {
        println!("// {label}");
        for (name, h) in &got {
            println!("(\"{name}\", {h:#018x}),");
        }
        return;
    }
    let got: Vec<(&str, u64)> = got.iter().map(|(n, h)| (n.as_str(), *h)).collect();
    assert_eq!(got, want, "{label}: outputs changed");
}

/// Runs `colcos args` into a fresh directory and checks what it wrote against `want`.
fn assert_golden(label: &str, args: &[&str], want: &[(&str, u64)]) {
    let dir = tempfile::tempdir().unwrap();
    check(label, run_into(args, dir.path()), want);
}

#[test]
fn default_scenario() {
    let args = [
        "run",
        "scenarios/three_trails.toml",
        "--duration",
        "6",
        "--quiet",
    ];
    assert_golden("three_trails", &args, THREE_TRAILS);
}

#[test]
fn case_studies_as_scenarios() {
    for (file, want) in [
        ("scenarios/case1_g3.toml", CASE1_G3),
        ("scenarios/case1_layout_b_g2.toml", CASE1_B_G2),
        ("scenarios/case2_alarm.toml", CASE2),
    ] {
        assert_golden(file, &["run", file, "--duration", "40", "--quiet"], want);
    }
}

#[test]
fn large_swarm() {
    let dir = tempfile::tempdir().unwrap();
    // Enough robots and deposits that every parallel path is taken (robots, banded deposits, field
    // rows), written out as a scenario file.
    let large = colcos_testkit::scenarios::large_swarm().build().unwrap();
    let scenario = common::write(dir.path(), "large.toml", &large.to_toml());
    let out = dir.path().join("out");
    let got = run_into(&["run", scenario.to_str().unwrap(), "--quiet"], &out);
    check("large swarm", got, LARGE);
}

#[test]
fn case_studies_as_experiments() {
    let args = [
        "experiment",
        "all",
        "--trials",
        "2",
        "--runs",
        "1",
        "--seed",
        "3",
        "--quiet",
    ];
    assert_golden("experiment all", &args, EXPERIMENTS);
}

const LARGE: &[(&str, u64)] = &[
    ("fields/blue.npy", 0x8d908e5e874be824),
    ("fields/red.npy", 0xfd1411c1d4918bc2),
    ("run.gif", 0x21cf3849ecb835b8),
    ("scenario.toml", 0x2dab784f4a77cac8),
    ("screen.png", 0xdc9665d6d7cb7c12),
    ("trajectory.csv", 0x68923c94eacf076b),
];
const THREE_TRAILS: &[(&str, u64)] = &[
    ("fields/blue.npy", 0xe74c302841f17da4),
    ("fields/green.npy", 0x89d694ea8364d769),
    ("fields/red.npy", 0x2e0af3a9c1f520c6),
    ("run.gif", 0xc007b5e11957ec9c),
    ("scenario.toml", 0x74f711f92dc9113d),
    ("screen.png", 0x72ad292a752be460),
    ("trajectory.csv", 0xc6a99e37cc59fa9c),
];
const CASE1_G3: &[(&str, u64)] = &[
    ("fields/LAP.npy", 0xc952b4dfdfe5505b),
    ("fields/SAP.npy", 0xdfff4a782f01fa42),
    ("fields/SRP.npy", 0xc2747a75adaa7feb),
    ("scenario.toml", 0xd468996410fb0dfb),
    ("screen.png", 0x2ee51d14a5cdd68a),
    ("trajectory.csv", 0xf9437d682ea6874b),
];
const CASE1_B_G2: &[(&str, u64)] = &[
    ("fields/LAP.npy", 0xbe447f50d106e252),
    ("fields/SAP.npy", 0xe8b8112fc4e75cb2),
    ("scenario.toml", 0xbbaf23960a581f0e),
    ("screen.png", 0xb8b059c87c25f51d),
    ("trajectory.csv", 0xde1ead4e65acaf5b),
];
const CASE2: &[(&str, u64)] = &[
    ("fields/AGP.npy", 0xef092f407a2741f0),
    ("fields/ALP.npy", 0x38f58f51f25a8a7d),
    ("run.gif", 0x67fd5a657f6a8bdc),
    ("scenario.toml", 0xa5510f9a43eda2bf),
    ("screen.png", 0xac4299743f8b4e06),
    ("trajectory.csv", 0x7722042f27594126),
];
const EXPERIMENTS: &[(&str, u64)] = &[
    ("case1/arrivals.csv", 0xf6dc22241692aefe),
    ("case1/fig5_arrivals.png", 0x15ba472f98e26fb0),
    ("case1/fig6_g3_trajectories.png", 0xdb9b6f9cc60c85fc),
    ("case1/trajectories_all_groups.png", 0x72876237a72b54c5),
    ("case1/trials.csv", 0x61d7146b94214dfe),
    ("case2/fig7_snapshots.png", 0x90f5c41f4bbc408f),
    ("case2/fig8_s_t.png", 0x9621ee8de0848569),
    ("case2/s_t.csv", 0xd9aa738430940183),
    ("case2/trajectories.png", 0x3325c03b2286fab9),
];
