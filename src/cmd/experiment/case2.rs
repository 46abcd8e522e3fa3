//! Case II: aggregation and alarm pheromones. `runs` independent runs of `scenarios/case2_alarm.toml`
//! (a leader, three followers, a wandering predator), sampled every `sample_every` seconds: S(t) of
//! eq. (9), whether any prey robot senses the alarm (which splits the run into aggregation and
//! dispersion phases) and every robot's position. The figures' screen snapshots come from running the
//! chosen run again to the chosen moments ([`snapshots_at`]): runs are deterministic per index.
use anyhow::{Context, Result};
use colcos_sim::behaviour::paper::RED;
use colcos_sim::metrics::{
    Phase, PhaseKind, phases, relative_fall, relative_rise, sum_distance_of,
};
use colcos_sim::output::draw;
use colcos_sim::prelude::*;
use colcos_sim::screen;

/// The scenario file of case II, compiled in.
pub const SCENARIO_TOML: &str = include_str!("../../../scenarios/case2_alarm.toml");

#[derive(Clone, Debug)]
pub struct Case2Config {
    pub scenario: Scenario,
    pub runs: usize,
    /// Seconds between S(t) samples.
    pub sample_every: f32,
    /// Width of the snapshots, pixels.
    pub snapshot_width: u32,
    /// Mean red intensity above which a robot senses the alarm (the behaviours' `alarm_threshold`).
    pub alarm_threshold: f32,
}

impl Case2Config {
    /// `runs` runs of the paper's scenario with `seed`.
    pub fn paper(runs: usize, seed: u64) -> Result<Self> {
        let scenario = Scenario::from_toml_str(SCENARIO_TOML, ".")
            .context("scenarios/case2_alarm.toml")?
            .with_overrides(Some(seed), None)?;
        Ok(Case2Config {
            scenario,
            runs,
            sample_every: 0.1,
            snapshot_width: 480,
            alarm_threshold: 0.05,
        })
    }
}

#[derive(Clone, Debug)]
pub struct Case2Run {
    pub times: Vec<f32>,
    /// Eq. (9), m.
    pub s: Vec<f32>,
    /// Any leader or follower senses the ALP.
    pub alarm: Vec<bool>,
    pub phases: Vec<Phase>,
    /// Per robot, its positions at the sample times.
    pub paths: Vec<Vec<Vec2>>,
    pub roles: Vec<String>,
    /// Largest relative fall of S over an aggregation phase (from the phase's start to its minimum).
    pub aggregation_fall: f32,
    /// Largest relative rise of S over a dispersion phase (from the alarm to the phase's maximum; None:
    /// no alarm in the run).
    pub alarm_rise: Option<f32>,
}

#[derive(Clone, Debug)]
pub struct Case2Result {
    pub config: Case2Config,
    pub runs: Vec<Case2Run>,
    pub wall_seconds: f64,
}

/// Robot colours in the pictures: leader, followers, predator.
pub fn role_colour(role: &str) -> image::Rgb<u8> {
    match role {
        "leader" => image::Rgb([255, 215, 0]),
        "predator" => image::Rgb([255, 255, 255]),
        _ => image::Rgb([90, 170, 255]),
    }
}

fn snapshot(world: &World, width: u32) -> image::RgbImage {
    let s = world.screen();
    let height = ((width as f32 * s.size[1] / s.size[0]).round() as u32).max(1);
    let mut img = screen::render(world.pheromones(), s, width, height);
    let colours: Vec<image::Rgb<u8>> = (0..world.robot_count())
        .map(|i| role_colour(world.role(i)))
        .collect();
    draw::robots(
        &mut img,
        s,
        world.poses(),
        world.robot_params().radius,
        &colours,
    );
    img
}

/// One run (world index `index`).
pub fn run_one(cfg: &Case2Config, index: usize) -> Result<Case2Run> {
    let mut world = World::with_index(&cfg.scenario, index as u64)?;
    let n = world.robot_count();
    let roles: Vec<String> = (0..n).map(|i| world.role(i).to_string()).collect();
    let leader = roles
        .iter()
        .position(|r| r == "leader")
        .context("case II needs a robot with role \"leader\"")?;
    let followers: Vec<usize> = (0..n).filter(|&i| roles[i] == "follower").collect();
    let prey: Vec<usize> = (0..n).filter(|&i| roles[i] != "predator").collect();
    let dt = world.dt();
    let every = ((cfg.sample_every / dt).round() as u64).max(1);
    let (mut times, mut s, mut alarm) = (Vec::new(), Vec::new(), Vec::new());
    let mut paths = vec![Vec::new(); n];
    let mut positions = Vec::with_capacity(n);
    let mut record = |world: &World| {
        positions.clear();
        positions.extend(world.poses().iter().map(|p| p.pos));
        times.push(world.time());
        s.push(sum_distance_of(&positions, leader, &followers));
        let obs = world.observations();
        alarm.push(
            prey.iter()
                .any(|&i| obs[i].strength(RED) > cfg.alarm_threshold),
        );
        for (p, q) in paths.iter_mut().zip(&positions) {
            p.push(*q);
        }
    };
    record(&world);
    while !world.is_finished() {
        world.step();
        if world.tick().is_multiple_of(every) {
            record(&world);
        }
    }
    let phases = phases(&times, &alarm);
    let aggregation_fall = phases
        .iter()
        .filter(|p| p.kind == PhaseKind::Aggregation)
        .map(|p| relative_fall(&s, p.first, p.last))
        .fold(0.0, f32::max);
    let alarm_rise = phases
        .iter()
        .filter(|p| p.kind == PhaseKind::Dispersion)
        .map(|p| relative_rise(&s, p.first, p.last))
        .reduce(f32::max);
    Ok(Case2Run {
        times,
        s,
        alarm,
        phases,
        paths,
        roles,
        aggregation_fall,
        alarm_rise,
    })
}

/// The screen of run `index` with the robots drawn on it at each of `times` (s, ascending), by running
/// that run again: the same world index gives the same run.
pub fn snapshots_at(
    cfg: &Case2Config,
    index: usize,
    times: &[f32],
) -> Result<Vec<image::RgbImage>> {
    let mut world = World::with_index(&cfg.scenario, index as u64)?;
    let dt = world.dt();
    let mut out = Vec::with_capacity(times.len());
    for &t in times {
        let tick = (t / dt).round() as u64;
        while world.tick() < tick && !world.is_finished() {
            world.step();
        }
        out.push(snapshot(&world, cfg.snapshot_width));
    }
    Ok(out)
}

/// Every run in parallel, gathered by run index. `tick` is called once per finished run.
pub fn run(cfg: &Case2Config, tick: &(dyn Fn() + Sync)) -> Result<Case2Result> {
    let started = std::time::Instant::now();
    let runs: Vec<Result<Case2Run>> =
        super::par_map_ticking(0..cfg.runs, tick, |i| run_one(cfg, i));
    let runs = runs.into_iter().collect::<Result<Vec<_>>>()?;
    Ok(Case2Result {
        config: cfg.clone(),
        runs,
        wall_seconds: started.elapsed().as_secs_f64(),
    })
}

/// `run,time,s,alarm,phase` rows.
pub fn s_t_csv(r: &Case2Result) -> String {
    let mut w = super::csv_writer(&["run", "time", "s", "alarm", "phase"]);
    for (k, run) in r.runs.iter().enumerate() {
        for (j, ((t, s), a)) in run.times.iter().zip(&run.s).zip(&run.alarm).enumerate() {
            let phase = run
                .phases
                .iter()
                .find(|p| p.first <= j && j <= p.last)
                .map_or("", |p| match p.kind {
                    PhaseKind::Aggregation => "aggregation",
                    PhaseKind::Dispersion => "dispersion",
                });
            let alarm = if *a { "1" } else { "0" };
            let row: [&str; 5] = [
                &k.to_string(),
                &format!("{t:.2}"),
                &format!("{s:.4}"),
                alarm,
                phase,
            ];
            w.write_record(row).expect("writing to memory");
        }
    }
    super::csv_text(w)
}
