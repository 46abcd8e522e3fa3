//! Golden outputs of the batched environment: observations, rewards, terminations and global state of
//! every task, under fixed actions and under a baseline policy, hash to exactly these values. A
//! refactoring that changes any of them changes behaviour. Each is pinned with the safety shield off
//! (the simulator alone) and on (the default: what every plant does to the agents' commands), for the
//! default solver (rapier) and for the disc solver.
//! `COLCOS_GOLDEN_PRINT=1 cargo test --release -p colcos-env --test golden -- --nocapture` prints them.
use colcos_env::baseline::BaselinePolicy;
use colcos_env::{Actions, EnvConfig, VecEnv};
use colcos_sim::robot::PhysicsBackend;

/// FNV-1a, 64-bit, over the bytes of every value fed to it.
struct Fnv(u64);
impl Fnv {
    fn bytes(&mut self, b: &[u8]) {
        for &x in b {
            self.0 = (self.0 ^ x as u64).wrapping_mul(0x0100_0000_01b3);
        }
    }
    fn floats(&mut self, v: &[f32]) {
        v.iter().for_each(|x| self.bytes(&x.to_le_bytes()));
    }
    fn flags(&mut self, v: &[bool]) {
        v.iter().for_each(|&x| self.bytes(&[x as u8]));
    }
}

fn record(env: &VecEnv, h: &mut Fnv) {
    h.floats(env.outputs().obs());
    h.floats(env.outputs().rewards());
    h.flags(env.outputs().terminated());
    h.flags(env.outputs().truncated());
    h.floats(env.outputs().state());
    h.floats(env.outputs().final_obs());
    h.flags(env.outputs().final_mask());
    // The task's per-episode memory (none for the first three tasks: nothing hashed).
    for w in 0..env.spec().num_envs {
        env.task_state(w)
            .iter()
            .for_each(|x| h.bytes(&x.to_le_bytes()));
    }
}

fn config(task: &str, shield: bool, physics: Option<PhysicsBackend>) -> EnvConfig {
    let mut c = EnvConfig::new(task);
    c.physics = physics;
    c.shield = shield;
    c.num_envs = 4;
    c.max_cycles = 40;
    c.seed = 11;
    c.num_threads = Some(2);
    c
}

/// Fixed, varied actions (a sine over world, agent, wheel and step) through two episodes.
fn scripted_actions(task: &str, shield: bool, physics: Option<PhysicsBackend>) -> u64 {
    let mut env = VecEnv::new(&config(task, shield, physics)).unwrap();
    let mut h = Fnv(0xcbf2_9ce4_8422_2325);
    env.reset(Some(11), None).unwrap();
    record(&env, &mut h);
    // Wheels and, where the task's agents lay pheromone, deposit rates (negative ones lay nothing).
    let len = env.spec().num_envs * env.spec().num_agents * env.action_decoder().width();
    for t in 0..90 {
        let a: Vec<f32> = (0..len)
            .map(|k| ((k * 7 + t * 3) as f32 * 0.37).sin())
            .collect();
        env.step(Actions::Continuous(&a)).unwrap();
        record(&env, &mut h);
    }
    h.0
}

/// The task's scenario behaviour as a baseline policy, through two episodes.
fn baseline(
    task: &str,
    behaviour: &str,
    params: serde_json::Value,
    shield: bool,
    physics: Option<PhysicsBackend>,
) -> u64 {
    let mut env = VecEnv::new(&config(task, shield, physics)).unwrap();
    env.reset(Some(5), None).unwrap();
    let mut policy = BaselinePolicy::new(&env, behaviour, &params, 5).unwrap();
    let mut h = Fnv(0xcbf2_9ce4_8422_2325);
    let mut a = vec![0.0; env.spec().num_envs * env.spec().num_agents * policy.width()];
    for _ in 0..90 {
        policy.act(&env, &mut a).unwrap();
        h.floats(&a);
        env.step(Actions::Continuous(&a)).unwrap();
        record(&env, &mut h);
    }
    h.0
}

fn check(label: &str, got: u64, want: u64) {
    if std::env::var("COLCOS_GOLDEN_PRINT").is_ok_and(|v| v == "1") {
        println!("{label}: {got:#018x}");
    } else {
        assert_eq!(got, want, "{label}: outputs changed ({got:#018x})");
    }
}

/// Every task under fixed actions, shield off and on, with `physics` (None: the scenario's).
fn fixed_actions(physics: Option<PhysicsBackend>, want: [(&str, u64, u64); 3]) {
    for (task, without, with) in want {
        let tag = physics.map_or("default".to_string(), |p| format!("{p:?}"));
        check(
            &format!("{task} [{tag}]"),
            scripted_actions(task, false, physics),
            without,
        );
        check(
            &format!("{task} (shield) [{tag}]"),
            scripted_actions(task, true, physics),
            with,
        );
    }
}

/// Every task's baseline policy, shield off and on.
fn baselines(physics: Option<PhysicsBackend>, want: [(u64, u64); 3]) {
    let policies = [
        ("aggregation", "aggregation_follower", serde_json::json!({})),
        ("foraging", "forage", serde_json::json!({})),
        ("trail", "follow", serde_json::json!({"channel": "b"})),
    ];
    for ((task, behaviour, params), (without, with)) in policies.into_iter().zip(want) {
        let tag = physics.map_or("default".to_string(), |p| format!("{p:?}"));
        let label = format!("{task}/{behaviour} [{tag}]");
        check(
            &label,
            baseline(task, behaviour, params.clone(), false, physics),
            without,
        );
        check(
            &format!("{label} (shield)"),
            baseline(task, behaviour, params, true, physics),
            with,
        );
    }
}

/// The default solver, rapier.
#[test]
fn every_task_under_fixed_actions() {
    fixed_actions(
        None,
        [
            ("aggregation", 0x3776c14bee7d36a5, 0xcaec0c8436a51332),
            ("foraging", 0x44a08f13ea024f94, 0x44a08f13ea024f94),
            ("trail", 0xc4f22a3d0cc98d4b, 0x66a9459e8ecf3087),
        ],
    );
}

#[test]
fn every_task_under_fixed_actions_discs() {
    fixed_actions(
        Some(PhysicsBackend::Discs),
        [
            ("aggregation", 0x6c90e24c4bc67b1a, 0x8654bbb86b0ec21d),
            ("foraging", 0xe84fe0d65f7cb0d5, 0xe84fe0d65f7cb0d5),
            ("trail", 0x673dabe31bf0b339, 0xca1859e673d199be),
        ],
    );
}

#[test]
fn baselines_rapier() {
    baselines(
        None,
        [
            (0xd79355c2a3ff1fe6, 0xdf0b28a4460102bf),
            (0xb32eb24480774581, 0xb32eb24480774581),
            (0xb51d54da9c6d30e4, 0x2b3944c75b4a06c9),
        ],
    );
}

#[test]
fn baselines_discs() {
    baselines(
        Some(PhysicsBackend::Discs),
        [
            (0xc00d1dd233e303a8, 0x974aa2e14e4c100b),
            (0xa43155483782abb3, 0xa43155483782abb3),
            (0x137cf18b419c7b0f, 0xd5407ffcbae572eb),
        ],
    );
}

/// The tasks whose agents lay pheromone, under fixed actions and under their own hand-written
/// policies, shield off and on (rapier): the rewards, the extra observation entry and the
/// per-episode memory included.
#[test]
fn the_pheromone_laying_tasks() {
    let want = [
        (
            "colony",
            "colony_ant",
            [
                0xa19175c4e2f4c3d3,
                0xa19175c4e2f4c3d3,
                0xe3e94bb67c44bf91,
                0x6b3844f12bf0c8a4,
            ],
        ),
        (
            "coverage",
            "coverage_walk",
            [
                0x01886a2c1929c08f,
                0x8bb8313c19fa22da,
                0x31233c6cdf874b7f,
                0x486f8b4772dd8c8c,
            ],
        ),
        (
            "alarm",
            "alarm_flee",
            [
                0xf92d3342a7318b8e,
                0x112846da77e510cd,
                0xb07caec582be7ce8,
                0x1b1a9051c25920c9,
            ],
        ),
    ];
    let null = serde_json::Value::Null;
    for (task, policy, [fixed, fixed_shield, hand, hand_shield]) in want {
        check(task, scripted_actions(task, false, None), fixed);
        check(
            &format!("{task} (shield)"),
            scripted_actions(task, true, None),
            fixed_shield,
        );
        let label = format!("{task}/{policy}");
        check(
            &label,
            baseline(task, policy, null.clone(), false, None),
            hand,
        );
        check(
            &format!("{label} (shield)"),
            baseline(task, policy, null.clone(), true, None),
            hand_shield,
        );
    }
}
