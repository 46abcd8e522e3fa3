//! Golden outputs: the default scenario and both case studies, run by the `colcos` binary with a fixed
//! seed, write exactly these bytes. A refactoring that changes any of them changes behaviour.
//! `COLCOS_GOLDEN_PRINT=1 cargo test --release --test golden -- --nocapture` prints the current hashes.
use std::path::Path;
use std::process::Command;

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

fn colcos(args: &[&str], out: &Path) -> Vec<(String, u64)> {
    let status = Command::new(env!("CARGO_BIN_EXE_colcos"))
        .args(args)
        .arg("--out")
        .arg(out)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .unwrap();
    assert!(
        status.status.success(),
        "colcos {args:?}: {}",
        String::from_utf8_lossy(&status.stderr)
    );
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

#[test]
fn default_scenario() {
    let dir = tempfile::tempdir().unwrap();
    let got = colcos(
        &[
            "run",
            "scenarios/three_trails.toml",
            "--duration",
            "6",
            "--quiet",
        ],
        dir.path(),
    );
    check("three_trails", got, THREE_TRAILS);
}

#[test]
fn case_studies_as_scenarios() {
    for (file, want) in [
        ("scenarios/case1_g3.toml", CASE1_G3),
        ("scenarios/case1_layout_b_g2.toml", CASE1_B_G2),
        ("scenarios/case2_alarm.toml", CASE2),
    ] {
        let dir = tempfile::tempdir().unwrap();
        let got = colcos(&["run", file, "--duration", "40", "--quiet"], dir.path());
        check(file, got, want);
    }
}

/// Enough robots and deposits that every parallel path is taken (robots, banded deposits, field rows).
const LARGE_SWARM: &str = r#"
duration = 0.4
seed = 7
[screen]
resolution = [3840, 2160]
size = [2.4, 1.35]
[field]
cell = 0.003
[output]
gif_interval = 0.2
[[pheromones]]
name = "red"
colour = [255, 0, 0]
evaporation = 5.0
diffusion = 1e-5
[[pheromones]]
name = "blue"
colour = [0, 0, 255]
evaporation = 5.0
diffusion = 1e-6
maps = [{ polyline = [[0.2, 0.2], [2.2, 1.1]], width = 0.05, rate = 0.2 }]
[[robots]]
count = 200
behaviour = "follow"
params = { channel = "b" }
deposits = [{ pheromone = "red", kernel = { shape = "cone", radius = 0.01 }, rate = 5.0 }]
[[robots]]
count = 150
behaviour = "avoid"
deposits = [{ pheromone = "blue", kernel = { shape = "disc", radius = 0.01 }, rate = 5.0 }]
"#;

#[test]
fn large_swarm() {
    let dir = tempfile::tempdir().unwrap();
    let scenario = dir.path().join("large.toml");
    std::fs::write(&scenario, LARGE_SWARM).unwrap();
    let out = dir.path().join("out");
    let got = colcos(&["run", scenario.to_str().unwrap(), "--quiet"], &out);
    check("large swarm", got, LARGE);
}

#[test]
fn case_studies_as_experiments() {
    let dir = tempfile::tempdir().unwrap();
    let got = colcos(
        &[
            "experiment",
            "all",
            "--trials",
            "2",
            "--runs",
            "1",
            "--seed",
            "3",
            "--quiet",
        ],
        dir.path(),
    );
    check("experiment all", got, EXPERIMENTS);
}

const LARGE: &[(&str, u64)] = &[
    ("fields/blue.npy", 0x8d908e5e874be824),
    ("fields/red.npy", 0xf65ce95708c8a76c),
    ("run.gif", 0x21cf3849ecb835b8),
    ("scenario.toml", 0x2dab784f4a77cac8),
    ("screen.png", 0x746a412740df9e7d),
    ("trajectory.csv", 0x9a541762d89d6b69),
];
const THREE_TRAILS: &[(&str, u64)] = &[
    ("fields/blue.npy", 0x84f3375c62076cfa),
    ("fields/green.npy", 0x441ef8aaab1f4688),
    ("fields/red.npy", 0x2e0af3a9c1f520c6),
    ("run.gif", 0xc007b5e11957ec9c),
    ("scenario.toml", 0x74f711f92dc9113d),
    ("screen.png", 0xe56a857e55daf0dc),
    ("trajectory.csv", 0x271f7d04f28e7b5e),
];
const CASE1_G3: &[(&str, u64)] = &[
    ("fields/LAP.npy", 0xc952b4dfdfe5505b),
    ("fields/SAP.npy", 0xdfff4a782f01fa42),
    ("fields/SRP.npy", 0xc2747a75adaa7feb),
    ("scenario.toml", 0xd468996410fb0dfb),
    ("screen.png", 0x2ee51d14a5cdd68a),
    ("trajectory.csv", 0x879f4ecacc86dd17),
];
const CASE1_B_G2: &[(&str, u64)] = &[
    ("fields/LAP.npy", 0xbe447f50d106e252),
    ("fields/SAP.npy", 0xe8b8112fc4e75cb2),
    ("scenario.toml", 0xbbaf23960a581f0e),
    ("screen.png", 0xb8b059c87c25f51d),
    ("trajectory.csv", 0xe485d82eecb9f116),
];
const CASE2: &[(&str, u64)] = &[
    ("fields/AGP.npy", 0x17190009229fb89e),
    ("fields/ALP.npy", 0x38f58f51f25a8a7d),
    ("run.gif", 0x3b1d1cf7031c1055),
    ("scenario.toml", 0xa5510f9a43eda2bf),
    ("screen.png", 0xbbf28eb896d3b7f8),
    ("trajectory.csv", 0x91b0e44b95d9172c),
];
const EXPERIMENTS: &[(&str, u64)] = &[
    ("case1/arrivals.csv", 0xf6dc22241692aefe),
    ("case1/fig5_arrivals.png", 0x15ba472f98e26fb0),
    ("case1/fig6_g3_trajectories.png", 0xdb9b6f9cc60c85fc),
    ("case1/trajectories_all_groups.png", 0x5a2fe42a38589961),
    ("case1/trials.csv", 0xdc8d0266aadd370d),
    ("case2/fig7_snapshots.png", 0xe98bfc2cdc3a975a),
    ("case2/fig8_s_t.png", 0xc7e92a7e2518f57a),
    ("case2/s_t.csv", 0x292c5b6fcdc98acd),
    ("case2/trajectories.png", 0x043f59ed69eb4dd8),
];
