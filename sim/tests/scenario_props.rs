//! Random mutations of every shipped scenario (`scenarios/`, `env/scenarios/`): numbers made 0,
//! negative, NaN, infinite, huge or tiny, arrays of the wrong length, keys removed or duplicated,
//! types swapped, odd strings. Each mutant goes to validation; each one it accepts must build a world
//! and step it, run one tick through the run library (every output file written) and save a
//! `scenario.toml` that validates again. No panic, no hang, no abort.
//!
//! The batch runs in a child process (this test binary again) under a memory limit (`ulimit -v`), so
//! an allocation that aborts or a step that never ends fails the parent test instead of the machine.
use colcos_sim::run::{self, RunOptions};
use colcos_sim::scenario::Scenario;
use colcos_sim::world::World;
use proptest::prelude::*;
use proptest::sample::Index;
use proptest::test_runner::{Config, RngAlgorithm, TestCaseError, TestRng, TestRunner};
use std::cell::Cell;
use std::path::Path;
use std::process::{Command, Stdio};
use std::sync::mpsc;
use std::time::{Duration, Instant};
use toml::Value;

/// Mutants per scenario file (11 files): a batch takes some seconds in the release profile. More
/// (and another seed) for a longer search: `COLCOS_SCENARIO_PROPS=CASES[,SEED]`.
const CASES: u32 = 48;
/// Longest one mutant may take to validate, build and step.
const CASE_LIMIT: Duration = Duration::from_secs(20);
/// Longest the whole batch may take.
const BATCH_LIMIT: Duration = Duration::from_secs(240);
/// The same with `COLCOS_SCENARIO_PROPS` set (a longer search, by hand).
const LONG_BATCH_LIMIT: Duration = Duration::from_secs(3600);
/// Address space of the child, KiB (the limits module bounds a world well below it).
const MEMORY_LIMIT_KIB: u64 = 6 << 20;
const CHILD_ENV: &str = "COLCOS_SCENARIO_PROPS_CHILD";

#[test]
fn mutated_scenarios_validate_and_run_under_time_and_memory_limits() {
    let exe = std::env::current_exe().unwrap();
    let mut child = Command::new("sh")
        .arg("-c")
        .arg(format!(
            "ulimit -v {MEMORY_LIMIT_KIB} && exec \"$0\" \"$@\""
        ))
        .arg(&exe)
        .args([
            "--exact",
            "mutation_batch",
            "--ignored",
            "--nocapture",
            "--test-threads=1",
        ])
        .env(CHILD_ENV, "1")
        // Address space, not memory, is limited: on a many-core machine each thread's stack and
        // malloc arena would count against it.
        .env("RAYON_NUM_THREADS", "2")
        .env("MALLOC_ARENA_MAX", "2")
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("starting the batch in a child process");
    let (tx, rx) = mpsc::channel();
    let stdout = child.stdout.take().unwrap();
    let stderr = child.stderr.take().unwrap();
    let read = |mut r: Box<dyn std::io::Read + Send>, tx: mpsc::Sender<String>| {
        std::thread::spawn(move || {
            let mut s = String::new();
            let _ = r.read_to_string(&mut s);
            let _ = tx.send(s);
        })
    };
    let a = read(Box::new(stdout), tx.clone());
    let b = read(Box::new(stderr), tx);
    let started = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break Some(status);
        }
        let limit = if std::env::var_os("COLCOS_SCENARIO_PROPS").is_some() {
            LONG_BATCH_LIMIT
        } else {
            BATCH_LIMIT
        };
        if started.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            break None;
        }
        std::thread::sleep(Duration::from_millis(50));
    };
    let _ = (a.join(), b.join());
    let output: String = rx.try_iter().collect::<Vec<_>>().join("\n");
    match status {
        None => panic!("the batch ran past {BATCH_LIMIT:?} (a hang?):\n{output}"),
        Some(s) if !s.success() => panic!("the batch failed ({s}):\n{output}"),
        Some(_) => {
            assert!(
                output.contains("mutants:"),
                "the batch printed no tally:\n{output}"
            );
            for line in output.lines().filter(|l| l.contains("mutants:")) {
                println!("{line}");
            }
        }
    }
}

/// The batch itself; run by the test above in a memory-limited child.
#[test]
#[ignore = "run in a memory-limited child by mutated_scenarios_validate_and_run_under_time_and_memory_limits"]
fn mutation_batch() {
    if std::env::var_os(CHILD_ENV).is_none() {
        eprintln!("note: running without the child's memory limit");
    }
    let files = colcos_testkit::scenarios::shipped(&["scenarios", "env/scenarios"]);
    assert!(files.len() >= 10, "scenario files: {files:?}");
    for (n, file) in files.iter().enumerate() {
        let text = std::fs::read_to_string(file).unwrap();
        let base = file.parent().unwrap().to_path_buf();
        let value: Value = text.parse::<toml::Table>().unwrap().into();
        let (cases, seed) = scale();
        let config = Config {
            cases,
            failure_persistence: None,
            max_shrink_iters: 64,
            ..Config::default()
        };
        let seed = [(n as u8 + 1).wrapping_add(seed); 32];
        let mut runner =
            TestRunner::new_with_rng(config, TestRng::from_seed(RngAlgorithm::ChaCha, &seed));
        let (accepted, refused) = (Cell::new(0u32), Cell::new(0u32));
        let result = runner.run(&mutations(), |muts| {
            let mutant = apply(&value, &muts);
            let tally = if check_and_step(mutant, &base)? {
                &accepted
            } else {
                &refused
            };
            tally.set(tally.get() + 1);
            Ok(())
        });
        if let Err(e) = result {
            panic!("{}: {e}", file.display());
        }
        println!(
            "{}: mutants: {} accepted and stepped, {} refused",
            file.file_name().unwrap().to_string_lossy(),
            accepted.get(),
            refused.get()
        );
    }
}

/// Mutants per file and a seed offset, from `COLCOS_SCENARIO_PROPS` (default: [`CASES`], 0).
fn scale() -> (u32, u8) {
    let Ok(v) = std::env::var("COLCOS_SCENARIO_PROPS") else {
        return (CASES, 0);
    };
    let mut parts = v.split(',').map(|p| p.trim().parse::<u32>());
    match (parts.next(), parts.next()) {
        (Some(Ok(c)), None) => (c, 0),
        (Some(Ok(c)), Some(Ok(s))) => (c, s as u8),
        _ => panic!("COLCOS_SCENARIO_PROPS = {v:?}: expected CASES or CASES,SEED"),
    }
}

/// Validates `text`; if accepted, builds the world, steps it once and re-validates the saved scenario,
/// all in a worker thread bounded by [`CASE_LIMIT`] (a hang ends the process with the mutant printed).
fn check_and_step(text: String, base: &Path) -> Result<bool, TestCaseError> {
    let (tx, rx) = mpsc::channel();
    let base = base.to_path_buf();
    let shown = text.clone();
    std::thread::spawn(move || {
        let result = std::panic::catch_unwind(|| -> Result<bool, String> {
            let Ok(sc) = Scenario::from_toml_str(&text, &base) else {
                return Ok(false);
            };
            let mut world =
                World::new(&sc).map_err(|e| format!("check accepted, run refused: {e}"))?;
            world.step();
            // The run library for one tick: the log, the GIF, the screen and the fields are written.
            let dt = sc.spec.dt;
            let one_tick = sc
                .clone()
                .with_overrides(None, Some(dt))
                .map_err(|e| format!("one tick of it is refused: {e}"))?;
            let out = tempfile::tempdir().map_err(|e| e.to_string())?;
            run::run(&one_tick, out.path(), RunOptions::default())
                .map_err(|e| format!("check accepted, the run library refused: {e}"))?;
            Scenario::from_toml_str(&sc.to_toml(), &base)
                .map_err(|e| format!("the saved scenario.toml does not validate again: {e}"))?;
            Ok(true)
        });
        let _ = tx.send(result);
    });
    match rx.recv_timeout(CASE_LIMIT) {
        Ok(Ok(Ok(accepted))) => Ok(accepted),
        Ok(Ok(Err(why))) => Err(TestCaseError::fail(format!("{why}\n--- mutant:\n{shown}"))),
        Ok(Err(_)) => Err(TestCaseError::fail(format!(
            "panicked\n--- mutant:\n{shown}"
        ))),
        Err(_) => {
            eprintln!("a mutant ran past {CASE_LIMIT:?}:\n{shown}");
            std::process::exit(3);
        }
    }
}

/// One change to a scenario's TOML tree (or its text), at the node picked by an index.
#[derive(Clone, Debug)]
enum Mutation {
    /// Replace the node by this value (numbers at the edges, strings, other types).
    Set(Index, Value),
    /// Multiply a number (integer or float) by this factor.
    Scale(Index, f64),
    /// Remove the node from its table or array.
    Remove(Index),
    /// Arrays: repeat an element, or keep only the first `n`.
    Grow(Index),
    Truncate(Index, usize),
    /// Text: repeat or drop one line of the serialized file (a duplicated key or table header).
    DuplicateLine(Index),
    DropLine(Index),
}

fn odd_value() -> impl Strategy<Value = Value> {
    prop_oneof![
        prop::sample::select(vec![
            0.0,
            -1.0,
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            1e30,
            1e-30,
            -1e-30,
            f64::MAX,
            f64::MIN_POSITIVE,
            0.5,
            1e9,
        ])
        .prop_map(Value::Float),
        prop::sample::select(vec![0i64, -1, 1, i64::MAX, i64::MIN, 1 << 32, 1_000_000, 3])
            .prop_map(Value::Integer),
        prop::sample::select(vec![
            "",
            "x",
            "nan",
            "../../../etc/passwd",
            "/dev/zero",
            "/proc/self/mem",
            "ünïcødé ✓",
            "gaussian",
            "grid",
            "explicit",
            "one_sided",
            "random",
            "tracked",
            "gpu",
        ])
        .prop_map(|s| Value::String(s.to_string())),
        Just(Value::Boolean(true)),
        Just(Value::Array(vec![])),
        Just(Value::Table(toml::Table::new())),
        Just(Value::Array(vec![Value::Float(1.0); 5])),
    ]
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        4 => (any::<Index>(), odd_value()).prop_map(|(i, v)| Mutation::Set(i, v)),
        3 => (
            any::<Index>(),
            prop::sample::select(vec![-1.0, 0.0, 1e-6, 0.01, 10.0, 1000.0, 1e6])
        )
            .prop_map(|(i, f)| Mutation::Scale(i, f)),
        2 => any::<Index>().prop_map(Mutation::Remove),
        1 => any::<Index>().prop_map(Mutation::Grow),
        1 => (any::<Index>(), 0usize..3).prop_map(|(i, n)| Mutation::Truncate(i, n)),
        1 => any::<Index>().prop_map(Mutation::DuplicateLine),
        1 => any::<Index>().prop_map(Mutation::DropLine),
    ]
}

fn mutations() -> impl Strategy<Value = Vec<Mutation>> {
    prop::collection::vec(mutation(), 1..=3)
}

#[derive(Clone, Debug)]
enum Seg {
    Key(String),
    At(usize),
}

/// Every node's path, the root's children first.
fn paths(v: &Value, here: &mut Vec<Seg>, out: &mut Vec<Vec<Seg>>) {
    match v {
        Value::Table(t) => {
            for (k, c) in t {
                here.push(Seg::Key(k.clone()));
                out.push(here.clone());
                paths(c, here, out);
                here.pop();
            }
        }
        Value::Array(a) => {
            for (n, c) in a.iter().enumerate() {
                here.push(Seg::At(n));
                out.push(here.clone());
                paths(c, here, out);
                here.pop();
            }
        }
        _ => {}
    }
}

fn node_mut<'a>(root: &'a mut Value, path: &[Seg]) -> Option<&'a mut Value> {
    path.iter().try_fold(root, |v, seg| match (seg, v) {
        (Seg::Key(k), Value::Table(t)) => t.get_mut(k),
        (Seg::At(n), Value::Array(a)) => a.get_mut(*n),
        _ => None,
    })
}

fn apply(original: &Value, muts: &[Mutation]) -> String {
    let mut root = original.clone();
    let mut line_edits = Vec::new();
    for m in muts {
        let mut all = Vec::new();
        paths(&root, &mut Vec::new(), &mut all);
        if all.is_empty() {
            break;
        }
        let pick = |i: &Index| all[i.index(all.len())].clone();
        match m {
            Mutation::Set(i, v) => {
                if let Some(node) = node_mut(&mut root, &pick(i)) {
                    *node = v.clone();
                }
            }
            Mutation::Scale(i, f) => {
                if let Some(node) = node_mut(&mut root, &pick(i)) {
                    match node {
                        Value::Integer(n) => *n = (*n as f64 * f) as i64,
                        Value::Float(x) => *x *= f,
                        _ => {}
                    }
                }
            }
            Mutation::Remove(i) => {
                let path = pick(i);
                let (last, parent) = path.split_last().unwrap();
                match (node_mut(&mut root, parent), last) {
                    (Some(Value::Table(t)), Seg::Key(k)) => {
                        t.remove(k);
                    }
                    (Some(Value::Array(a)), Seg::At(n)) => {
                        a.remove(*n);
                    }
                    _ => {}
                }
            }
            Mutation::Grow(i) | Mutation::Truncate(i, _) => {
                let path = pick(i);
                let (_, parent) = path.split_last().unwrap();
                if let Some(Value::Array(a)) = node_mut(&mut root, parent) {
                    match m {
                        Mutation::Truncate(_, n) => a.truncate(*n),
                        _ => {
                            let first = a[0].clone();
                            a.push(first);
                        }
                    }
                }
            }
            Mutation::DuplicateLine(i) => line_edits.push((*i, true)),
            Mutation::DropLine(i) => line_edits.push((*i, false)),
        }
    }
    let text = toml::to_string(&root).unwrap_or_default();
    let mut lines: Vec<&str> = text.lines().collect();
    for (i, duplicate) in line_edits {
        if lines.is_empty() {
            break;
        }
        let n = i.index(lines.len());
        if duplicate {
            lines.insert(n, lines[n]);
        } else {
            lines.remove(n);
        }
    }
    lines.join("\n")
}
