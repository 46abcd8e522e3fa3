//! Pheromone actions: an agent laying at a constant fraction of `max_rate` lays byte for byte what a
//! scripted `deposits` rule of that rate lays (all but the dot a scripted rule lays at each start as
//! the world is built, before any agent has chosen); a zero action lays nothing; the discrete product of
//! motions and lay bits lays at the full rate; bad declarations and actions are refused by name.
use colcos_env::{ActionKind, Actions, EnvConfig, ScenarioSource, VecEnv};
use colcos_sim::field::FieldModel;
use colcos_sim::scenario::{EmitSpec, PheromoneSpec, Scenario};

const TRAIL: &str = include_str!("../scenarios/trail.toml");
const SCRIPTED: &str = r#"deposits = [{ pheromone = "red", kernel = { shape = "disc", radius = 0.008 }, rate = 3.0 }]"#;

/// The `trail` task's scenario without its static blue loop, which the task brings to steady state
/// with one still step before the episode: a step in which a scripted rule lays and no agent has
/// chosen anything yet.
fn base() -> String {
    let map = TRAIL
        .find("[[pheromones.maps]]")
        .expect("the trail scenario has a map");
    let end = TRAIL[map..]
        .find("\n\n")
        .expect("a blank line after the map")
        + map;
    assert!(TRAIL.contains(SCRIPTED), "the trail scenario changed");
    format!("{}{}", &TRAIL[..map], &TRAIL[end..])
}

/// That scenario with its agents' red trail replaced by `line`.
fn trail_with(line: &str) -> String {
    base().replace(SCRIPTED, line)
}

fn action_line(max_rate: f32) -> String {
    format!(
        r#"deposit_actions = [{{ pheromone = "red", kernel = {{ shape = "disc", radius = 0.008 }}, max_rate = {max_rate:?} }}]"#
    )
}

fn env(text: String, action: ActionKind) -> VecEnv {
    let mut cfg = EnvConfig::new("trail");
    cfg.scenario = ScenarioSource::Text(text);
    cfg.num_envs = 3;
    cfg.num_threads = Some(2);
    cfg.max_cycles = 1000;
    cfg.seed = 7;
    cfg.action = action;
    let mut env = VecEnv::new(&cfg).unwrap();
    env.reset(Some(7), None).unwrap();
    env
}

/// Every world's red field after `steps` steps of agents driving ahead, each row of the action
/// `[0.6, 0.4, extra...]`.
fn red_after(env: &mut VecEnv, extra: &[f32], steps: usize) -> Vec<Vec<f32>> {
    let s = env.spec().clone();
    let row: Vec<f32> = [0.6, 0.4].iter().chain(extra).copied().collect();
    let a: Vec<f32> = (0..s.num_envs * s.num_agents)
        .flat_map(|_| row.clone())
        .collect();
    for _ in 0..steps {
        env.step(Actions::Continuous(&a)).unwrap();
    }
    (0..s.num_envs).map(|e| red(env, e)).collect()
}

fn red(env: &VecEnv, e: usize) -> Vec<f32> {
    match &env.world(e).unwrap().pheromones()[0].model {
        FieldModel::Grid(g) => g.values().to_vec(),
        _ => panic!("red is a grid pheromone"),
    }
}

/// Each world's cells away from every robot's start: a scripted rule lays a dot there as the world
/// is built, before any agent has chosen anything (an agent's action applies from its first step).
fn away_from_starts(env: &VecEnv) -> Vec<Vec<bool>> {
    (0..env.spec().num_envs)
        .map(|e| {
            let world = env.world(e).unwrap();
            let FieldModel::Grid(g) = &world.pheromones()[0].model else {
                panic!("red is a grid pheromone")
            };
            let spec = *g.spec();
            let starts: Vec<_> = world.tracked().iter().map(|t| t.pose.pos).collect();
            (0..spec.nx * spec.ny)
                .map(|k| {
                    let c = glam::Vec2::new(
                        ((k % spec.nx) as f32 + 0.5) * spec.cell,
                        ((k / spec.nx) as f32 + 0.5) * spec.cell,
                    );
                    starts
                        .iter()
                        .all(|s| s.distance(c) > 0.008 + 2.0 * spec.cell)
                })
                .collect()
        })
        .collect()
}

/// Asserts two sets of fields equal bit for bit on the cells `keep` marks (and somewhere laid),
/// naming the first cell that differs.
#[track_caller]
fn assert_same(got: &[Vec<f32>], want: &[Vec<f32>], keep: &[Vec<bool>]) {
    let mut laid = 0;
    for (w, ((g, e), keep)) in got.iter().zip(want).zip(keep).enumerate() {
        assert_eq!(g.len(), e.len());
        let mut cells = (0..g.len()).filter(|&k| keep[k]);
        if let Some(k) = cells.find(|&k| g[k].to_bits() != e[k].to_bits()) {
            panic!("world {w}, cell {k}: {} laid, {} expected", g[k], e[k]);
        }
        laid += (0..g.len()).filter(|&k| keep[k] && e[k] > 0.0).count();
    }
    assert!(laid > 100, "only {laid} cells laid away from the starts");
}

#[test]
fn a_constant_deposit_action_lays_what_a_scripted_rule_of_that_rate_lays() {
    let mut scripted = env(base(), ActionKind::Continuous);
    let mut chosen = env(trail_with(&action_line(6.0)), ActionKind::Continuous);
    assert_eq!(chosen.spec().action.flat_len(), 3);
    let keep = away_from_starts(&scripted);
    let want = red_after(&mut scripted, &[], 150);
    let got = red_after(&mut chosen, &[0.5], 150);
    assert!(want[0].iter().any(|&v| v > 0.0), "the trail laid nothing");
    assert_same(&got, &want, &keep);
}

#[test]
fn a_zero_deposit_action_lays_nothing() {
    let mut none = env(trail_with(""), ActionKind::Continuous);
    let mut zero = env(trail_with(&action_line(6.0)), ActionKind::Continuous);
    let want = red_after(&mut none, &[], 100);
    let got = red_after(&mut zero, &[0.0], 100);
    assert!(got.iter().flatten().all(|&v| v == 0.0));
    assert_eq!(got, want);
}

#[test]
fn discrete_actions_lay_at_the_full_rate_when_their_bit_is_set() {
    let mut scripted = env(base(), ActionKind::Discrete);
    let mut chosen = env(trail_with(&action_line(3.0)), ActionKind::Discrete);
    assert_eq!(
        chosen.spec().action,
        colcos_env::Space::Discrete { n: 12 },
        "6 motions x lay or not"
    );
    let (e, n) = (chosen.spec().num_envs, chosen.spec().num_agents);
    let keep = away_from_starts(&scripted);
    for _ in 0..120 {
        // Forward (1) for the scripted rule; forward and lay (1 + 6) for the agents' choice.
        scripted.step(Actions::Discrete(&vec![1; e * n])).unwrap();
        chosen.step(Actions::Discrete(&vec![7; e * n])).unwrap();
    }
    let red_all = |env: &VecEnv| (0..e).map(|w| red(env, w)).collect::<Vec<_>>();
    assert_same(&red_all(&chosen), &red_all(&scripted), &keep);
}

#[test]
fn bad_deposit_actions_are_refused_by_name() {
    let build = |text: String| {
        let mut cfg = EnvConfig::new("trail");
        cfg.scenario = ScenarioSource::Text(text);
        VecEnv::new(&cfg).err().map(|e| e.to_string())
    };
    let unknown = build(trail_with(&action_line(6.0).replace("\"red\"", "\"cyan\""))).unwrap();
    assert!(
        unknown.contains("robots[0].deposit_actions[0].pheromone") && unknown.contains("cyan"),
        "{unknown}"
    );
    for bad in ["-1.0", "nan", "inf"] {
        let text = trail_with(&action_line(6.0).replace("6.0", bad));
        let err = build(text).unwrap();
        assert!(
            err.contains("robots[0].deposit_actions[0].max_rate"),
            "{bad}: {err}"
        );
    }

    // The wrong width, and a non-finite rate, named.
    let mut env = env(trail_with(&action_line(6.0)), ActionKind::Continuous);
    let s = env.spec().clone();
    let two = vec![0.0; s.num_envs * s.num_agents * 2];
    let err = env.step(Actions::Continuous(&two)).unwrap_err().to_string();
    assert!(err.contains("(2 wheels + 1 deposit rates)"), "{err}");
    let mut three = vec![0.0; s.num_envs * s.num_agents * 3];
    three[5] = f32::INFINITY;
    let err = env
        .step(Actions::Continuous(&three))
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("world 0, agent robot_1, deposit rate 0 is inf"),
        "{err}"
    );
}

/// A gaussian `alarm` pheromone each agent switches on and off (`when = "action"`), after its red
/// trail: actions `[left, right, red rate, alarm switch]`.
fn with_alarm_switch() -> String {
    let mut sc = Scenario::from_toml_str(&trail_with(&action_line(3.0)), ".").unwrap();
    sc.spec
        .pheromones
        .push(PheromoneSpec::gaussian("alarm", [0.0, 255.0, 0.0]).with_evaporation(1.0));
    sc.spec.robots[0]
        .emits
        .push(EmitSpec::follow("alarm", 0.01, [0.03, 0.03], 1.0).when_action());
    sc.to_toml()
}

/// Worlds whose agents' alarm sources have been switched on.
fn alarms_on(env: &VecEnv) -> Vec<usize> {
    (0..env.spec().num_envs)
        .map(|e| {
            let world = env.world(e).unwrap();
            let FieldModel::Gaussian(g) = &world.pheromones()[2].model else {
                panic!("alarm is gaussian")
            };
            g.sources.iter().filter(|s| s.start.is_finite()).count()
        })
        .collect()
}

#[test]
fn an_agent_switches_a_gaussian_emitter_with_its_last_action_entry() {
    let mut env = env(with_alarm_switch(), ActionKind::Continuous);
    assert_eq!(env.spec().action.flat_len(), 4);
    red_after(&mut env, &[0.0, 0.3], 5);
    assert_eq!(alarms_on(&env), [0, 0, 0], "below 0.5 is off");
    red_after(&mut env, &[0.0, 1.0], 1);
    assert_eq!(alarms_on(&env), [4, 4, 4], "every agent's source is on");
    // Discrete: 6 motions x 2 bits; bit 1 (the alarm) is on from action 6 * 2.
    let mut discrete = self::env(with_alarm_switch(), ActionKind::Discrete);
    let n = discrete.spec().num_envs * discrete.spec().num_agents;
    discrete
        .step(Actions::Discrete(&vec![1 + 6 * 2; n]))
        .unwrap();
    assert_eq!(alarms_on(&discrete), [4, 4, 4]);
}

#[test]
fn an_action_switched_emitter_on_robots_that_are_not_agents_is_refused() {
    let walker = r#"
[[robots]]
count = 1
role = "walker"
behaviour = "wander"
emits = [{ pheromone = "alarm", k = 0.01, sigma = [0.03, 0.03], evaporation = 1.0, when = "action" }]
"#;
    let mut cfg = EnvConfig::new("trail");
    cfg.scenario = ScenarioSource::Text(with_alarm_switch() + walker);
    let err = VecEnv::new(&cfg).err().expect("refused").to_string();
    assert!(
        err.contains("robots[1].emits") && err.contains("nothing would switch it"),
        "{err}"
    );
}
