//! Running the runs: one world per run (world index 0 of its scenario, whose seed is the run's seed,
//! so a row is reproduced by `colcos run` of the same scenario and seed), stepped to its end with the
//! metrics recorded; all pending runs in parallel on a rayon pool, each row appended to the table as
//! its run finishes. Nothing depends on the order runs finish in or on the number of threads.
use crate::error::{Result, SweepError};
use crate::metrics::Recorder;
use crate::plan::Plan;
use crate::table::ResultsTable;
use colcos_sim::behaviour::WheelCommand;
use colcos_sim::field::FieldModel;
use colcos_sim::scenario::Scenario;
use colcos_sim::world::World;
use glam::Vec2;
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::Instant;

/// One finished run.
#[derive(Clone, Debug, PartialEq)]
pub struct RunRow {
    pub id: u64,
    pub combo: usize,
    pub seed: u64,
    /// One per metric column; `None`: an empty cell.
    pub metrics: Vec<Option<f64>>,
    /// Wall time of the run, s.
    pub wall_s: f64,
}

impl RunRow {
    /// The row's cells in the order of `plan.columns`.
    pub fn fields(&self, plan: &Plan) -> Vec<String> {
        let mut f = vec![self.id.to_string(), self.combo.to_string()];
        f.extend(plan.combos[self.combo].iter().map(value_text));
        f.push(self.seed.to_string());
        f.extend(self.metrics.iter().map(|m| match m {
            Some(v) if v.is_finite() => v.to_string(),
            _ => String::new(),
        }));
        // Columns of metrics computed elsewhere, filled in by their caller.
        f.extend(plan.extra_metrics.iter().map(|_| String::new()));
        f.push(format!("{:.6}", self.wall_s));
        f
    }
}

/// A TOML value as a table cell: numbers as Rust prints them, strings without quotes.
pub fn value_text(v: &toml::Value) -> String {
    match v {
        toml::Value::Float(f) => f.to_string(),
        toml::Value::Integer(i) => i.to_string(),
        toml::Value::String(s) => s.clone(),
        toml::Value::Boolean(b) => b.to_string(),
        other => other.to_string(),
    }
}

/// Runs `id` of `plan` on its (checked) scenario.
pub fn run_one(plan: &Plan, id: u64, scenario: &Scenario) -> Result<RunRow> {
    run_inner(plan, id, scenario, None)
}

/// The same run, also recording the robots' poses at the metrics' sample times (for metrics computed
/// elsewhere, such as Python callables).
pub fn run_traced(plan: &Plan, id: u64, scenario: &Scenario) -> Result<(RunRow, Trace)> {
    let mut trace = Trace::default();
    let row = run_inner(plan, id, scenario, Some(&mut trace))?;
    Ok((row, trace))
}

fn run_inner(
    plan: &Plan,
    id: u64,
    scenario: &Scenario,
    mut trace: Option<&mut Trace>,
) -> Result<RunRow> {
    let (combo, seed) = plan.locate(id)?;
    let started = Instant::now();
    let mut world = World::new(scenario).map_err(|e| SweepError::Run {
        id,
        message: e.to_string(),
    })?;
    if plan.spec.preload_steady_state {
        preload_steady_state(&mut world);
        // One still step, so that the first observation a robot acts on sees the loaded fields.
        let stop = vec![WheelCommand::STOP; world.robot_count()];
        world.step_with_commands(&stop);
    }
    let mut recorder = Recorder::new(&plan.metrics, &world);
    let every = ((plan.metrics.options.sample_every / world.dt()).round() as u64).max(1);
    if let Some(t) = trace.as_deref_mut() {
        t.roles = (0..world.robot_count())
            .map(|i| world.role(i).to_string())
            .collect();
        t.record(&world);
    }
    let end_on_arrival = plan.metrics.options.end_on_arrival;
    while !world.is_finished() {
        world.step();
        recorder.after_step(&world);
        if let Some(t) = trace.as_deref_mut()
            && world.tick().is_multiple_of(every)
        {
            t.record(&world);
        }
        if end_on_arrival && recorder.all_arrived() {
            break;
        }
    }
    let metrics = recorder.finish(&world);
    Ok(RunRow {
        id,
        combo,
        seed,
        metrics,
        wall_s: started.elapsed().as_secs_f64(),
    })
}

/// The robots' true poses at the sample times of a run (t = 0 and every `sample_every`).
#[derive(Clone, Debug, Default)]
pub struct Trace {
    /// Sample times, s.
    pub times: Vec<f32>,
    /// `[t][robot][x, y]`, m, flattened.
    pub positions: Vec<f32>,
    /// `[t][robot]`, rad, flattened.
    pub headings: Vec<f32>,
    pub roles: Vec<String>,
}

impl Trace {
    fn record(&mut self, world: &World) {
        self.times.push(world.time());
        for p in world.poses() {
            self.positions.extend([p.pos.x, p.pos.y]);
            self.headings.push(p.heading);
        }
    }
}

/// Runs the given ids (each scenario built and checked here), in parallel on the current rayon pool,
/// in id order. What a remote worker (a Ray task) calls.
pub fn run_ids(plan: &Plan, ids: &[u64]) -> Result<Vec<RunRow>> {
    ids.par_iter()
        .map(|&id| run_one(plan, id, &plan.scenario(id)?))
        .collect()
}

/// Sets every static grid field with no diffusion or wind to its steady state `e J` and freezes it
/// (`Phi <- a Phi + e (1 - a) J` keeps `Phi = e J` for ever, so this is exact).
pub fn preload_steady_state(world: &mut World) {
    for p in world.pheromones_mut() {
        if let FieldModel::Grid(g) = &mut p.model {
            let params = g.params();
            if params.diffusion == 0.0 && params.wind == Vec2::ZERO && g.fill_steady_state() {
                g.freeze();
            }
        }
    }
}

/// How a local sweep runs.
#[derive(Default)]
pub struct SweepOptions<'a> {
    /// Worker threads; `None`: all cores.
    pub threads: Option<usize>,
    /// Insist on a table to continue (a rerun into the same directory resumes anyway).
    pub resume: bool,
    /// Called after each row is written with (rows done, runs in all).
    pub on_row: Option<&'a (dyn Fn(u64, u64) + Sync)>,
    /// Set to stop starting runs; the rows written stay, and a later run resumes.
    pub stop: Option<&'a AtomicBool>,
}

/// What a sweep did.
#[derive(Clone, Debug)]
pub struct SweepReport {
    pub total: u64,
    /// Rows found complete in the table before this call.
    pub skipped: u64,
    /// Runs this call ran.
    pub ran: u64,
    pub table: PathBuf,
    pub wall_s: f64,
    /// Stopped before every run was done (resume to finish).
    pub interrupted: bool,
}

/// Checks every combination, then runs what the table in `out_dir` does not yet hold.
pub fn run_sweep(plan: &Plan, out_dir: &Path, opts: SweepOptions<'_>) -> Result<SweepReport> {
    let started = Instant::now();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(opts.threads.unwrap_or(0))
        .build()
        .map_err(|e| SweepError::Run {
            id: 0,
            message: format!("starting the thread pool: {e}"),
        })?;
    let scenarios = pool.install(|| plan.check_all())?;
    let table = ResultsTable::open(out_dir, plan, opts.resume)?;
    let skipped = table.done().len() as u64;
    let pending: Vec<u64> = (0..plan.total())
        .filter(|&id| !table.contains(id))
        .collect();
    let total = plan.total();
    let done = AtomicU64::new(skipped);
    let ran = AtomicU64::new(0);
    let table = Mutex::new(table);
    if let Some(f) = opts.on_row {
        f(skipped, total);
    }
    let stopped = || opts.stop.is_some_and(|s| s.load(Ordering::Relaxed));
    pool.install(|| {
        pending.par_iter().try_for_each(|&id| {
            if stopped() {
                return Ok(());
            }
            let row = run_one(plan, id, &scenarios[id as usize])?;
            let fields = row.fields(plan);
            table
                .lock()
                .unwrap_or_else(|e| e.into_inner())
                .append(id, &fields)?;
            ran.fetch_add(1, Ordering::Relaxed);
            let n = done.fetch_add(1, Ordering::Relaxed) + 1;
            if let Some(f) = opts.on_row {
                f(n, total);
            }
            Ok::<(), SweepError>(())
        })
    })?;
    let table = table.into_inner().unwrap_or_else(|e| e.into_inner());
    let complete = table.done().len() as u64 == total;
    let path = table.path().to_path_buf();
    if complete {
        table.finish_sorted()?;
    }
    Ok(SweepReport {
        total,
        skipped,
        ran: ran.into_inner(),
        table: path,
        wall_s: started.elapsed().as_secs_f64(),
        interrupted: !complete,
    })
}
