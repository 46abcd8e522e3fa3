//! `docs/scenarios.md` names every scenario key. The keys come from the spec types themselves: every
//! table of a fully populated scenario is probed with an unknown key, and the "expected one of ..."
//! list serde answers with is the struct's complete field list (optional fields included), so a field
//! added to any spec struct fails this test until it is documented.
use colcos_sim::scenario::{ScenarioSpec, parse_spec};
use serde::Deserialize;
use std::collections::BTreeSet;
use std::path::Path;

const PROBE: &str = "__undocumented_probe";

/// Every key set, with each kernel shape, map kind, placement and `when` form, and a non-default rig.
const POPULATED: &str = r#"
name = "everything"
duration = 10.0
dt = 0.02
seed = 3
physics = "discs"

[arena]
size = [1.0, 0.8]

[[obstacles]]
shape = "box"
kind = "physical"
centre = [0.5, 0.4]
size = [0.1, 0.05]
angle = 30.0
radius = 0.05
points = [[0.1, 0.1], [0.2, 0.1], [0.2, 0.2]]
thickness = 0.01
image = "mask.png"
channel = "a"
threshold = 128
pixels = [64, 48]

[screen]
resolution = [1920, 1080]
size = [1.2, 0.7]

[field]
cell = 0.01
inject_at = "true"
backend = "cpu"

[robot]
radius = 0.02
mass = 0.05
wheel_base = 0.026
max_wheel_speed = 0.35
motor_lag = 0.05

[sensor]
footprint_radius = 0.0015
gamma = 2.2
crosstalk = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
gain = 1500.0
integration_ms = 24.0
dark_counts = 30.0
noise = 8.0

[bumper]
range = 0.02
angles = [0.7, 0.0, -0.7]

[tracker]
rate_hz = 30.0
latency = 0.04
position_noise = 0.001
heading_noise = 0.02
dropout = 0.01

[output]
gif_interval = 0.2
gif_width = 480
log_every = 1

[[pheromones]]
name = "trail"
colour = [0, 0, 255]
model = "grid"
evaporation = 20.0
diffusion = 2e-6
scheme = "implicit"
wind = [0.01, 0.0]
maps = [
  { polyline = [[0.1, 0.1], [0.5, 0.5]], width = 0.02, rate = 0.02 },
  { image = "map.png", channel = "b", rate = 0.02 },
]

[[pheromones]]
name = "cloud"
colour = [0, 255, 0]
model = "gaussian"
evaporation = 10.0
sources = [{ k = 1.0, sigma = [0.1, 0.2], rho = 0.1, evaporation = 5.0, centre = [0.5, 0.4], start = 1.0 }]

[[robots]]
count = 1
role = "leader"
behaviour = "wander"
params = { speed = 0.1 }
placement = "explicit"
region = [0.0, 0.0, 1.0, 0.8]
poses = [[0.5, 0.4, 90.0]]
deposits = [
  { pheromone = "trail", kernel = { shape = "disc", radius = 0.01 }, rate = 1.0 },
  { pheromone = "trail", kernel = { shape = "cone", radius = 0.01 }, rate = 1.0 },
  { pheromone = "trail", kernel = { shape = "gaussian", sigma = 0.005 }, rate = 1.0 },
]
emits = [
  { pheromone = "cloud", k = 0.5, sigma = [0.1, 0.1], rho = 0.0, evaporation = 5.0, when = "follow" },
  { pheromone = "cloud", k = 0.5, sigma = [0.1, 0.1], evaporation = 5.0, when = { near = { role = "leader", distance = 0.2 } } },
]

[rig]
tracker_ids = [7]
radio_ids = [3]
sensors = "robot"
firmware = "motion"
latency = 0.05
telemetry_hz = 4.0
keepalive_hz = 8.0
tracker_silence = 0.2
pose_age = 0.4
policy_stall = 0.3
shield = { max_wheel_speed = 0.3, margin = 0.04, horizon = 0.2 }

[randomize]
tracker_latency = [0.03, 0.08]
position_noise = [0.0, 0.003]
heading_noise = [0.0, 0.05]
sensor_gain = [0.8, 1.2]
crosstalk = [0.0, 0.05]
motor_lag = [0.02, 0.1]
max_wheel_speed = [0.2, 0.3]
"#;

/// One step from the root to a nested table.
#[derive(Clone)]
enum Step {
    Key(String),
    Index(usize),
}

fn table_at<'a>(root: &'a mut toml::Value, at: &[Step]) -> &'a mut toml::Table {
    let mut v = root;
    for step in at {
        v = match step {
            Step::Key(k) => v.get_mut(k.as_str()).expect("key on the walked path"),
            Step::Index(i) => v.get_mut(*i).expect("index on the walked path"),
        };
    }
    v.as_table_mut().expect("a table on the walked path")
}

/// What a table of the spec is, by serde's answer to an unknown key in it.
enum Probe {
    /// Any key goes: a behaviour's `params` (documented with the behaviours, not here).
    FreeForm,
    /// Not a struct (an enum's variant map such as `when = { near = ... }`): only its keys count.
    Variants,
    /// A struct and every field it accepts, optional ones included.
    Fields(Vec<String>),
}

fn probe(root: &toml::Value, at: &[Step]) -> Probe {
    let mut probed = root.clone();
    table_at(&mut probed, at).insert(PROBE.into(), toml::Value::Integer(0));
    let message = match ScenarioSpec::deserialize(probed) {
        Ok(_) => return Probe::FreeForm,
        Err(e) => e.to_string(),
    };
    match message.split_once(&format!("unknown field `{PROBE}`, expected")) {
        // The deserialiser appends the table's path on a line of its own ("in `arena`").
        Some((_, expected)) => Probe::Fields(
            expected
                .lines()
                .next()
                .unwrap_or_default()
                .split('`')
                .skip(1)
                .step_by(2)
                .map(str::to_string)
                .collect(),
        ),
        None => Probe::Variants,
    }
}

/// Collects the documentation path (`robots[].deposits[].kernel.radius`) of every key of the table at
/// `at`: the keys it holds and the fields its struct accepts; then descends into nested tables.
fn walk(root: &toml::Value, at: Vec<Step>, prefix: &str, keys: &mut BTreeSet<String>) {
    let join = |k: &str| {
        if prefix.is_empty() {
            k.to_string()
        } else {
            format!("{prefix}.{k}")
        }
    };
    match probe(root, &at) {
        Probe::FreeForm => return,
        Probe::Variants => {}
        Probe::Fields(fields) => keys.extend(fields.iter().map(|f| join(f))),
    }
    let mut probe_root = root.clone();
    let table = table_at(&mut probe_root, &at).clone();
    for (k, v) in &table {
        keys.insert(join(k));
        let mut next = at.clone();
        next.push(Step::Key(k.clone()));
        match v {
            toml::Value::Table(_) => walk(root, next, &join(k), keys),
            toml::Value::Array(items) => {
                for (i, item) in items.iter().enumerate() {
                    if item.is_table() {
                        let mut each = next.clone();
                        each.push(Step::Index(i));
                        walk(root, each, &format!("{}[]", join(k)), keys);
                    }
                }
            }
            _ => {}
        }
    }
}

/// The key paths of a spec, after a serde round trip (so defaults are filled in).
fn key_paths(spec: &ScenarioSpec) -> BTreeSet<String> {
    let root = toml::Value::try_from(spec).expect("a spec serialises");
    let mut keys = BTreeSet::new();
    walk(&root, Vec::new(), "", &mut keys);
    keys
}

fn read(path: &str) -> String {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    std::fs::read_to_string(root.join(path)).unwrap_or_else(|e| panic!("{path}: {e}"))
}

#[test]
fn every_scenario_key_is_in_the_reference() {
    let doc = read("docs/scenarios.md");
    let mut keys = BTreeSet::new();
    let populated = parse_spec(POPULATED).expect("the populated scenario parses");
    keys.extend(key_paths(&populated));
    keys.extend(key_paths(
        &parse_spec("duration = 1.0").expect("a minimal scenario parses"),
    ));
    for file in ["scenarios/case2_alarm.toml", "scenarios/three_trails.toml"] {
        keys.extend(key_paths(
            &parse_spec(&read(file)).unwrap_or_else(|e| panic!("{file}: {e}")),
        ));
    }
    // The walk must have reached the deepest tables, or it proves nothing.
    for deep in [
        "robot.wheel_base",
        "pheromones[].maps[].polyline",
        "pheromones[].maps[].image",
        "pheromones[].sources[].sigma",
        "robots[].deposits[].kernel.radius",
        "robots[].deposits[].kernel.sigma",
        "robots[].emits[].when.near.distance",
        "rig.shield.margin",
    ] {
        assert!(keys.contains(deep), "the walk missed `{deep}`: {keys:?}");
    }
    let missing: Vec<_> = keys
        .iter()
        .filter(|k| !doc.contains(&format!("`{k}`")))
        .collect();
    assert!(
        missing.is_empty(),
        "docs/scenarios.md does not document these scenario keys (write each as `path`): {missing:?}"
    );
}
