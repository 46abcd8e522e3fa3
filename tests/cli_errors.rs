//! Bad input on the command line, or in the scenario it names, is a clear error at once: exit status
//! non-zero, the key or flag named, no panic. And what `colcos check` accepts, `colcos run` runs.
mod common;
use colcos_testkit::parsing::TRAIL_AVOIDERS;
use common::succeeded;
use std::path::Path;
use std::process::Output;

/// A 0.1 s run of three robots avoiding each other, without a GIF.
fn good() -> String {
    TRAIL_AVOIDERS.replace(
        "duration = 1.0",
        "duration = 0.1\n[output]\ngif_interval = 0.0",
    )
}

fn colcos(args: &[&str]) -> Output {
    common::colcos(args).output().expect("colcos runs")
}

#[track_caller]
fn assert_fails(args: &[&str], needles: &[&str]) {
    let out = colcos(args);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{args:?} succeeded: {stderr}");
    assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
    for n in needles {
        assert!(
            stderr.contains(n),
            "{args:?}: {stderr:?} does not mention {n:?}"
        );
    }
}

fn write(dir: &Path, name: &str, text: &str) -> String {
    let path = common::write(dir, name, text);
    path.to_str().unwrap().to_owned()
}

#[test]
fn check_refuses_what_run_would_refuse_when_building() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let out = out.to_str().unwrap();
    let image = write(
        dir.path(),
        "image.toml",
        &good().replace(
            "evaporation = 10.0",
            "evaporation = 10.0\nmaps = [{ image = \"missing.png\", rate = 1 }]",
        ),
    );
    let crowded = write(
        dir.path(),
        "crowded.toml",
        &good().replace("count = 3", "count = 25\nregion = [0.5, 0.5, 0.7, 0.7]"),
    );
    for (file, key) in [
        (&image, "pheromones[0].maps[0].image"),
        (&crowded, "robots[0].placement"),
    ] {
        assert_fails(&["check", file], &[key]);
        assert_fails(&["run", file, "--quiet", "--out", out], &[key]);
    }
}

#[test]
fn a_checked_scenario_runs() {
    let dir = tempfile::tempdir().unwrap();
    let file = write(dir.path(), "good.toml", &good());
    assert!(colcos(&["check", &file]).status.success());
    let out = dir.path().join("out");
    let run = colcos(&["run", &file, "--quiet", "--out", out.to_str().unwrap()]);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
}

fn strs(args: &[String]) -> Vec<&str> {
    args.iter().map(String::as_str).collect()
}

#[test]
fn run_arguments_are_bounded() {
    let dir = tempfile::tempdir().unwrap();
    let file = write(dir.path(), "good.toml", &good());
    let out = dir.path().join("out");
    let out = out.to_str().unwrap();
    let run = |extra: &[&'static str]| -> Vec<String> {
        let base = ["run", file.as_str(), "--quiet", "--out", out];
        base.iter().chain(extra).map(|a| a.to_string()).collect()
    };
    assert_fails(&strs(&run(&["--threads", "0"])), &["--threads", "1..=1024"]);
    assert_fails(
        &strs(&run(&["--threads", "5000"])),
        &["--threads", "1..=1024"],
    );
    assert_fails(&strs(&run(&["--duration=-1"])), &["duration", "-1"]);
    assert_fails(&strs(&run(&["--duration", "NaN"])), &["duration", "NaN"]);
    assert_fails(&strs(&run(&["--duration", "inf"])), &["duration"]);
    assert!(!Path::new(out).join("trajectory.csv").exists());
}

/// Ctrl-C (SIGINT) and SIGTERM end `colcos run` after the current step with every output complete:
/// the summary says it was interrupted, the screen, fields and GIF are whole files, and every
/// trajectory row is complete.
#[test]
fn an_interrupted_run_leaves_complete_outputs() {
    for signal in ["-INT", "-TERM"] {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("out");
        let mut child = common::colcos(&[
            "run",
            "scenarios/three_trails.toml",
            "--duration",
            "600",
            "--quiet",
            "--out",
        ])
        .arg(&out)
        .stdout(std::process::Stdio::piped())
        .spawn()
        .unwrap();
        // Let it get going (the trajectory grows past its header).
        let log = out.join("trajectory.csv");
        let t0 = std::time::Instant::now();
        while std::fs::metadata(&log).map(|m| m.len()).unwrap_or(0) < 100_000 {
            assert!(t0.elapsed().as_secs() < 60, "the run did not start");
            std::thread::sleep(std::time::Duration::from_millis(50));
        }
        let status = std::process::Command::new("kill")
            .args([signal, &child.id().to_string()])
            .status()
            .unwrap();
        assert!(status.success());
        let exit = child.wait().unwrap();
        assert!(exit.success(), "{signal}: {exit:?}");
        let summary = std::fs::read_to_string(out.join("summary.json")).unwrap();
        assert!(summary.contains("\"interrupted\": true"), "{summary}");
        image::open(out.join("screen.png")).expect("a whole screen.png");
        let gif = std::fs::read(out.join("run.gif")).unwrap();
        assert_eq!(gif.last(), Some(&0x3B), "the GIF has its trailer");
        for f in ["red", "green", "blue"] {
            assert!(
                std::fs::metadata(out.join(format!("fields/{f}.npy")))
                    .unwrap()
                    .len()
                    > 128
            );
        }
        let text = std::fs::read_to_string(&log).unwrap();
        assert!(text.ends_with('\n'));
        let columns = text.lines().next().unwrap().split(',').count();
        assert!(text.lines().all(|l| l.split(',').count() == columns));
    }
}

/// A second run into the same `--out` replaces the first one's files all together: a run without a
/// GIF and with other pheromones leaves no GIF or field of the first behind.
#[test]
fn a_second_run_into_the_same_directory_replaces_the_first() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let run = |scenario: &str| {
        succeeded(
            common::colcos(&["run", scenario, "--duration", "0.4", "--quiet", "--out"]).arg(&out),
        );
    };
    run("scenarios/three_trails.toml");
    assert!(out.join("run.gif").exists() && out.join("fields/red.npy").exists());
    std::fs::write(out.join("notes.txt"), "mine").unwrap();
    // case I: no GIF (gif_interval 0) and other pheromone names.
    run("scenarios/case1_g3.toml");
    assert!(
        !out.join("run.gif").exists(),
        "the first run's GIF was left behind"
    );
    assert!(
        !out.join("fields/red.npy").exists(),
        "the first run's field was left behind"
    );
    assert!(out.join("fields/LAP.npy").exists());
    assert_eq!(
        std::fs::read_to_string(out.join("notes.txt")).unwrap(),
        "mine"
    );
}

/// The error is printed once, on one line per cause, and says `needle` exactly once.
#[track_caller]
fn assert_says_once(args: &[&str], needles: &[&str], never: &[&str]) {
    let out = colcos(args);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{args:?} succeeded");
    assert_eq!(stderr.matches("error:").count(), 1, "{stderr}");
    for n in needles {
        assert_eq!(stderr.matches(n).count(), 1, "{n:?} in {stderr:?}");
    }
    for n in never {
        assert!(!stderr.contains(n), "{n:?} in {stderr:?}");
    }
}

/// Scenario mistakes a first scenario makes name the key the file wrote and its value, once.
#[test]
fn scenario_errors_name_the_key_and_value_the_file_wrote() {
    let dir = tempfile::tempdir().unwrap();
    let with =
        |name: &str, from: &str, to: &str| write(dir.path(), name, &good().replace(from, to));
    // A behaviour parameter of the wrong type: its value, not a placeholder.
    let params = with(
        "params.toml",
        "behaviour = \"avoid\"",
        "behaviour = \"avoid\"\nparams = { speed = \"fast\" }",
    );
    assert_says_once(
        &["check", &params],
        &["`robots[0].params.speed` = \"fast\"", "expected f32"],
        &["see message", "in `speed`"],
    );
    // A kernel's size: the key is the kernel's `radius`.
    let kernel = with(
        "kernel.toml",
        "behaviour = \"avoid\"",
        "behaviour = \"avoid\"\ndeposits = [{ pheromone = \"trail\", kernel = { shape = \"disc\", radius = -0.01 }, rate = 1.0 }]",
    );
    assert_says_once(
        &["check", &kernel],
        &["`robots[0].deposits[0].kernel.radius` = -0.01"],
        &[],
    );
    // The screen's size is the screen's, even where the arena takes it.
    let screen = with(
        "screen.toml",
        "[output]",
        "[screen]\nsize = [-1.0, 0.8]\n[output]",
    );
    assert_says_once(&["check", &screen], &["`screen.size[0]` = -1"], &["arena"]);
    let arena = with(
        "arena.toml",
        "[output]",
        "[arena]\nsize = [1.0, 0.0]\n[output]",
    );
    assert_says_once(&["check", &arena], &["`arena.size[1]` = 0"], &[]);
    // A heading that is not a number is a heading error, not a position one.
    let heading = with(
        "heading.toml",
        "count = 3",
        "count = 1\nplacement = \"explicit\"\nposes = [[0.5, 0.5, nan]]",
    );
    assert_says_once(
        &["check", &heading],
        &["`robots[0].poses[0][2]` = NaN", "heading"],
        &["not inside the arena"],
    );
    let outside = with(
        "outside.toml",
        "count = 3",
        "count = 1\nplacement = \"explicit\"\nposes = [[5.0, 0.5, 0.0]]",
    );
    assert_says_once(
        &[
            "run",
            &outside,
            "--quiet",
            "--out",
            dir.path().join("o").to_str().unwrap(),
        ],
        &[
            "`robots[0].poses[0]`",
            "not inside the arena: x must be in [0.02, ",
        ],
        &[],
    );
}

/// A missing scenario file: the OS's reason once, not once per layer of the error.
#[test]
fn a_missing_file_is_reported_once() {
    assert_says_once(
        &["run", "no/such/scenario.toml", "--quiet"],
        &["no/such/scenario.toml", "(os error 2)"],
        &[],
    );
    assert_says_once(&["check", "no/such/scenario.toml"], &["(os error 2)"], &[]);
}

/// `--help` says what the default output directory is named after: the file, not the `name` key.
#[test]
fn run_help_says_the_default_out_uses_the_file_name() {
    let out = colcos(&["run", "--help"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success());
    assert!(
        text.contains("runs/<scenario file name without .toml>"),
        "{text}"
    );
}

/// A run's report prints the simulated time rounded, and a GPU-capable run prints no libwayland
/// complaint when `XDG_RUNTIME_DIR` is unset (GPU drivers probe for Wayland through it).
#[test]
fn a_run_reports_cleanly_without_xdg_runtime_dir() {
    let dir = tempfile::tempdir().unwrap();
    let file = write(dir.path(), "good.toml", &good());
    let out = common::colcos(&["run", &file, "--backend", "auto", "--out"])
        .arg(dir.path().join("o"))
        .env_remove("XDG_RUNTIME_DIR")
        .output()
        .unwrap();
    let (stdout, stderr) = (
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr),
    );
    assert!(out.status.success(), "{stderr}");
    assert!(stdout.contains("(0.10 s simulated)"), "{stdout}");
    assert!(!stderr.contains("XDG_RUNTIME_DIR"), "{stderr}");
}
