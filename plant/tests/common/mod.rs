//! What the plant tests share: the task they run and a twin plant brought to rest on it.
use colcos_env::{Actions, EnvConfig};
use colcos_plant::{LiveEnv, PlantKind, PlantOptions};

/// The aggregation task, 120 cycles an episode.
pub fn config() -> EnvConfig {
    let mut cfg = EnvConfig::new("aggregation");
    cfg.max_cycles = 120;
    cfg
}

/// A twin plant of [`config`] whose robots start where the scenario places them (no `goto`), its
/// options edited by `edit`, reset with seed 5 and held still for `still` steps; and its number of
/// agents.
pub fn twin_at_rest(edit: impl FnOnce(&mut PlantOptions), still: usize) -> (LiveEnv, usize) {
    let mut opts = PlantOptions::new(PlantKind::Twin);
    opts.goto = false;
    edit(&mut opts);
    let mut env = LiveEnv::new(&config(), &opts).unwrap();
    env.reset(Some(5)).unwrap();
    let n = env.spec().num_agents;
    for _ in 0..still {
        env.step(Actions::Continuous(&vec![0.0; 2 * n])).unwrap();
    }
    (env, n)
}
