//! A deferred step (a task written in Python): the worlds move in `step_deferred`, and `conclude`
//! hands out the rewards and terminations given for the whole batch. Given the Rust task's own, the
//! outputs are those of a plain step, through terminations, truncations and both autoreset modes.
use colcos_env::{Actions, AutoresetMode, EnvConfig, VecEnv};

fn config(task: &str, mode: AutoresetMode) -> EnvConfig {
    let mut c = EnvConfig::new(task);
    c.num_envs = 5;
    c.num_threads = Some(2);
    c.max_cycles = 30;
    c.seed = 3;
    c.autoreset = mode;
    c
}

#[test]
fn given_the_tasks_own_rewards_a_deferred_step_is_a_plain_step() {
    for mode in [AutoresetMode::NextStep, AutoresetMode::SameStep] {
        let mut plain = VecEnv::new(&config("aggregation", mode)).unwrap();
        let mut deferred = VecEnv::new(&config("aggregation", mode)).unwrap();
        plain.reset(Some(3), None).unwrap();
        deferred.reset(Some(3), None).unwrap();
        let len = plain.spec().num_envs * plain.spec().num_agents * 2;
        let mut terminations = 0;
        for t in 0..75 {
            let a: Vec<f32> = (0..len)
                .map(|k| ((k * 5 + t) as f32 * 0.41).sin())
                .collect();
            plain.step(Actions::Continuous(&a)).unwrap();
            deferred.step_deferred(Actions::Continuous(&a)).unwrap();
            // What a Python task would have said: here, the Rust task's verdict, and every agent of
            // world 1 terminated at step 10.
            let mut terminated = plain.outputs().terminated().to_vec();
            if t == 10 {
                let n = plain.spec().num_agents;
                terminated[n..2 * n].fill(true);
            }
            deferred
                .conclude(plain.outputs().rewards(), &terminated)
                .unwrap();
            if t == 10 {
                assert!(deferred.outputs().terminated()[plain.spec().num_agents]);
                terminations += 1;
                continue;
            }
            if t < 10 {
                assert_eq!(
                    deferred.outputs().obs(),
                    plain.outputs().obs(),
                    "{mode:?} step {t}"
                );
                assert_eq!(deferred.outputs().rewards(), plain.outputs().rewards());
                assert_eq!(deferred.outputs().truncated(), plain.outputs().truncated());
                assert_eq!(
                    deferred.outputs().final_mask(),
                    plain.outputs().final_mask()
                );
            }
        }
        assert_eq!(terminations, 1);
        // World 1 ended early: its episode count is ahead of the plain run's.
        assert_eq!(deferred.episode(1), plain.episode(1) + 1, "{mode:?}");
        assert_eq!(deferred.episode(0), plain.episode(0));
    }
}

#[test]
fn a_deferred_step_must_be_concluded_with_one_value_per_agent() {
    let mut env = VecEnv::new(&config("trail", AutoresetMode::NextStep)).unwrap();
    env.reset(None, None).unwrap();
    let (e, n) = (env.spec().num_envs, env.spec().num_agents);
    let a = vec![0.2; e * n * 2];
    let err = env.conclude(&vec![0.0; e * n], &vec![false; e * n]);
    assert!(err.unwrap_err().to_string().contains("step_deferred"));
    env.step_deferred(Actions::Continuous(&a)).unwrap();
    let again = env.step(Actions::Continuous(&a)).unwrap_err().to_string();
    assert!(again.contains("conclude"), "{again}");
    let short = env.conclude(&[0.0], &[false]).unwrap_err().to_string();
    assert!(short.contains(&format!("expected {}", e * n)), "{short}");
    let mut bad = vec![0.0; e * n];
    bad[n + 1] = f32::NAN;
    let nan = env
        .conclude(&bad, &vec![false; e * n])
        .unwrap_err()
        .to_string();
    assert!(nan.contains("world 1, agent robot_1"), "{nan}");
    env.conclude(&vec![1.5; e * n], &vec![false; e * n])
        .unwrap();
    assert!(env.outputs().rewards().iter().all(|&r| r == 1.5));
}
