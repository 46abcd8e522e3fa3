//! Case I on random trail maps (`colcos experiment case1 --maps random --count N`): groups G1-G3 on
//! each of `count` maps of [`random_map`](super::random_map), `trials` trials per group and map, with
//! per-map and pooled arrivals at food, timeouts and G1's spread over the end points.
use super::case1::{self, Case1Config, Case1Result};
use super::random_map::{MapRules, RandomMap, coin_share, random_maps};
use anyhow::Result;
use colcos_sim::metrics::TrialOutcome;
use colcos_sim::rng::mix64;
use rayon::prelude::*;
use serde::Serialize;

/// Case I on one random map.
pub struct MapRun {
    pub map: RandomMap,
    pub result: Case1Result,
}

/// Case I on every random map.
pub struct RandomCase1 {
    pub seed: u64,
    pub trials: usize,
    pub maps: Vec<MapRun>,
    pub wall_seconds: f64,
}

/// The (map, group, trial) tasks, for a shared progress count.
pub fn task_count(count: usize, trials: usize) -> usize {
    count * case1::GROUPS.len() * trials
}

/// Generates the maps of `seed` and runs every group's trials on each (all in parallel; results are
/// gathered by map, group and trial index, so they do not depend on the thread count).
pub fn run(
    seed: u64,
    count: usize,
    trials: usize,
    forage: &toml::Table,
    tick: &(dyn Fn() + Sync),
) -> Result<RandomCase1> {
    let started = std::time::Instant::now();
    let maps = random_maps(seed, count, &MapRules::default())?;
    let runs: Vec<Result<MapRun>> = maps
        .into_par_iter()
        .enumerate()
        .map(|(i, map)| {
            // Each map's trials draw from their own streams (the same trial index on two maps differs).
            let mut cfg = Case1Config::new(map.layout.clone(), trials, mix64(seed ^ i as u64));
            cfg.foods = map.foods.clone();
            cfg.forage = forage.clone();
            let result = case1::run(&cfg, tick)?;
            Ok(MapRun { map, result })
        })
        .collect();
    Ok(RandomCase1 {
        seed,
        trials,
        maps: runs.into_iter().collect::<Result<_>>()?,
        wall_seconds: started.elapsed().as_secs_f64(),
    })
}

/// The numbers of one map, or of all pooled.
#[derive(Clone, Debug, Default, Serialize)]
pub struct Tally {
    /// Trials per group.
    pub trials: usize,
    /// Arrivals at a food point, G1, G2, G3.
    pub at_food: [usize; 3],
    /// Timeouts, G1, G2, G3.
    pub timeouts: [usize; 3],
    /// G1: expected arrivals at food for a fair coin at every fork (sum over trials).
    pub g1_coin_expected: f64,
    /// G1: end points reached at least once, and end points in all.
    pub g1_ends_reached: usize,
    pub ends: usize,
}

impl Tally {
    pub fn of(run: &MapRun) -> Self {
        let r = &run.result;
        let foods = &r.config.foods;
        let mut t = Tally {
            trials: r.config.trials,
            ends: run.map.layout.ends.len(),
            g1_ends_reached: r.groups[0].counts.distinct_points(),
            g1_coin_expected: coin_share(&run.map.layout, foods) * r.config.trials as f64,
            ..Tally::default()
        };
        for (g, grp) in r.groups.iter().enumerate() {
            t.at_food[g] = grp.at_food(foods);
            t.timeouts[g] = grp.counts.timeouts;
        }
        t
    }

    pub fn add(&mut self, o: &Tally) {
        self.trials += o.trials;
        for g in 0..3 {
            self.at_food[g] += o.at_food[g];
            self.timeouts[g] += o.timeouts[g];
        }
        self.g1_coin_expected += o.g1_coin_expected;
        self.g1_ends_reached += o.g1_ends_reached;
        self.ends += o.ends;
    }

    pub fn share(&self, g: usize) -> f64 {
        self.at_food[g] as f64 / self.trials.max(1) as f64
    }
}

/// The bars, measured: G3 at food >= 95 % pooled and >= 85 % on every map, G1 < G2 < G3
/// pooled, G1's arrivals at food within 3 standard deviations of the fair-coin expectation.
#[derive(Clone, Debug, Serialize)]
pub struct RandomClaims {
    pub pooled: Tally,
    pub g3_pooled_share: f64,
    pub g3_worst_map_share: f64,
    pub g3_worst_map: String,
    pub g3_ok: bool,
    pub order_ok: bool,
    /// (observed - expected) / sd of G1's arrivals at food under the fair-coin model.
    pub g1_coin_z: f64,
    pub g1_ok: bool,
}

pub fn claims(r: &RandomCase1) -> RandomClaims {
    let mut pooled = Tally::default();
    let mut worst = (f64::INFINITY, String::new());
    let mut var = 0.0;
    for m in &r.maps {
        let t = Tally::of(m);
        pooled.add(&t);
        if t.share(2) < worst.0 {
            worst = (t.share(2), m.map.layout.name.clone());
        }
        let p = coin_share(&m.map.layout, &m.result.config.foods);
        var += t.trials as f64 * p * (1.0 - p);
    }
    let z = (pooled.at_food[0] as f64 - pooled.g1_coin_expected) / var.sqrt().max(1e-9);
    let g3 = pooled.share(2);
    RandomClaims {
        g3_pooled_share: g3,
        g3_worst_map_share: worst.0,
        g3_worst_map: worst.1,
        g3_ok: g3 >= 0.95 && worst.0 >= 0.85,
        order_ok: pooled.at_food[0] < pooled.at_food[1] && pooled.at_food[1] < pooled.at_food[2],
        g1_coin_z: z,
        g1_ok: z.abs() <= 3.0,
        pooled,
    }
}

/// One row per map: how it was drawn and what each group did.
pub fn maps_csv(r: &RandomCase1) -> String {
    let mut w = super::csv_writer(&[
        "map",
        "nest_heading_deg",
        "depth",
        "ends",
        "foods",
        "corners",
        "trials",
        "g1_at_food",
        "g2_at_food",
        "g3_at_food",
        "g1_timeouts",
        "g2_timeouts",
        "g3_timeouts",
        "g1_coin_expected",
        "g1_ends_reached",
    ]);
    for m in &r.maps {
        let t = Tally::of(m);
        let l = &m.map.layout;
        let foods: Vec<String> = m.map.foods.iter().map(|f| f.to_string()).collect();
        let row = [
            l.name.clone(),
            format!("{}", l.nest().heading_deg),
            m.map.depth.to_string(),
            t.ends.to_string(),
            foods.join(" "),
            format!("{:?}", l.corners).to_lowercase(),
            t.trials.to_string(),
            t.at_food[0].to_string(),
            t.at_food[1].to_string(),
            t.at_food[2].to_string(),
            t.timeouts[0].to_string(),
            t.timeouts[1].to_string(),
            t.timeouts[2].to_string(),
            format!("{:.2}", t.g1_coin_expected),
            t.g1_ends_reached.to_string(),
        ];
        w.write_record(&row).expect("writing to memory");
    }
    super::csv_text(w)
}

/// The G3 trials of a map that did not end at food, by index.
pub fn g3_failures(m: &MapRun) -> Vec<usize> {
    let foods = &m.result.config.foods;
    m.result.groups[2]
        .trials
        .iter()
        .enumerate()
        .filter(|(_, t)| match t.outcome {
            TrialOutcome::Arrived { point, .. } => !foods.contains(&(point + 1)),
            TrialOutcome::TimedOut => true,
        })
        .map(|(k, _)| k)
        .collect()
}

fn pct(n: usize, of: usize) -> String {
    format!("{n}/{of} ({:.1} %)", 100.0 * n as f64 / of.max(1) as f64)
}

/// The table a person reads (`summary.md` and the console).
pub fn markdown(r: &RandomCase1) -> String {
    let c = claims(r);
    let p = &c.pooled;
    let ok = |b: bool| if b { "yes" } else { "**no**" };
    let mut s = format!(
        "# Case I on {} random trail maps (seed {}, {} trials per group and map)\n\n",
        r.maps.len(),
        r.seed,
        r.trials
    );
    s += "| pooled | at food | timeouts |\n| --- | --- | --- |\n";
    for (g, (name, ph)) in case1::GROUPS.iter().enumerate() {
        s += &format!(
            "| {name} ({}) | {} | {} |\n",
            ph.join(" + "),
            pct(p.at_food[g], p.trials),
            p.timeouts[g]
        );
    }
    s += &format!(
        "\n| claim | measured | holds |\n| --- | --- | --- |\n\
         | G3 at food >= 95 % pooled, >= 85 % on every map | {:.1} % pooled, worst map {} {:.0} % | {} |\n\
         | G1 < G2 < G3 pooled | {} < {} < {} | {} |\n\
         | G1 at food as a fair coin at every fork predicts | {} observed, {:.1} expected (z = {:.2}); {} of {} end points reached | {} |\n",
        100.0 * c.g3_pooled_share,
        c.g3_worst_map,
        100.0 * c.g3_worst_map_share,
        ok(c.g3_ok),
        p.at_food[0],
        p.at_food[1],
        p.at_food[2],
        ok(c.order_ok),
        p.at_food[0],
        p.g1_coin_expected,
        c.g1_coin_z,
        p.g1_ends_reached,
        p.ends,
        ok(c.g1_ok),
    );
    let failing: Vec<String> = r
        .maps
        .iter()
        .filter_map(|m| {
            let f = g3_failures(m);
            (!f.is_empty()).then(|| format!("{} ({} of {})", m.map.layout.name, f.len(), r.trials))
        })
        .collect();
    s += &format!(
        "\nMaps where a G3 trial missed the food: {}.\n\nwall time {:.1} s\n",
        if failing.is_empty() {
            "none".to_string()
        } else {
            failing.join(", ")
        },
        r.wall_seconds
    );
    s
}
