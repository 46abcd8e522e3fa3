//! `colcos experiment {case1,case2,all}`: the paper's two case studies, every trial in parallel, with
//! their figures and a summary table beside the paper's numbers.
//!
//! Case I ([`case1`]): groups G1 (LAP), G2 (LAP + SAP), G3 (LAP + SAP + SRP) on a trail map generated
//! from a tree ([`layout`]); arrivals per end point. Case II ([`case2`]): a leader, three followers and a
//! predator under the aggregation (AGP) and alarm (ALP) pheromones; S(t) of eq. (9) with its phases.
//! Results are deterministic per seed: each trial is its own world with its own random streams, and
//! results are gathered by trial index, never by completion order.
pub mod case1;
pub mod case2;
pub mod fig6;
pub mod fig78;
pub mod layout;
pub mod moments;
pub mod plots;
pub mod random_map;
pub mod random_plots;
pub mod random_run;
pub mod summary;

use anyhow::{Context, Result, bail};
use std::path::{Path, PathBuf};

/// Which case studies to run.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Which {
    Case1,
    Case2,
    All,
}

/// Which trail maps case I runs on.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum Maps {
    /// The layout of `--layout` (A or B).
    #[default]
    Layout,
    /// `--count` random maps by the paper's rule (seeded by `--seed`).
    Random,
}

/// Arguments of `colcos experiment`.
#[derive(Clone, Debug, clap::Args)]
pub struct ExperimentArgs {
    /// case1, case2 or all.
    #[arg(value_enum)]
    pub which: Which,
    /// Trials per group in case I (the paper: 20).
    #[arg(long, default_value_t = 20)]
    pub trials: usize,
    /// Independent runs of case II (the figures show the first).
    #[arg(long, default_value_t = 4)]
    pub runs: usize,
    /// Output directory.
    #[arg(long, default_value = "runs/experiment")]
    pub out: PathBuf,
    /// Seed of every random stream.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Trail layout of case I: A (default) or B.
    #[arg(long, default_value = "A")]
    pub layout: String,
    /// Available food points of case I, 1-based, comma separated [default: the layout's, A: 3,10].
    #[arg(long, value_delimiter = ',')]
    pub foods: Option<Vec<usize>>,
    /// Trail maps of case I: layout (the one of --layout) or random (--count maps drawn by the
    /// paper's rule, each with its own food points).
    #[arg(long, value_enum, default_value_t = Maps::Layout)]
    pub maps: Maps,
    /// Random maps of case I (with --maps random).
    #[arg(long, default_value_t = 10)]
    pub count: usize,
    /// Worker threads (default: all cores). Results do not depend on it.
    #[arg(long)]
    pub threads: Option<usize>,
    /// No progress bar.
    #[arg(long)]
    pub quiet: bool,
}

/// Options of a whole experiment, as the library takes them.
#[derive(Clone, Debug)]
pub struct Options {
    pub which: Which,
    pub trials: usize,
    pub runs: usize,
    pub out: PathBuf,
    pub seed: u64,
    pub layout: layout::TrailLayout,
    pub foods: Vec<usize>,
    /// Case I on this many random maps instead of `layout`.
    pub random_maps: Option<usize>,
    pub progress: bool,
}

impl Options {
    /// The defaults of the command line: 20 trials per group, 4 case-II runs, layout A, foods 3 and 10.
    pub fn new(which: Which, out: impl Into<PathBuf>) -> Self {
        let layout = layout::TrailLayout::a();
        let foods = layout.default_foods();
        Options {
            which,
            trials: 20,
            runs: 4,
            out: out.into(),
            seed: 1,
            layout,
            foods,
            random_maps: None,
            progress: false,
        }
    }

    pub fn from_args(a: &ExperimentArgs) -> Result<Self> {
        let Some(layout) = layout::TrailLayout::by_name(&a.layout) else {
            bail!("unknown layout {:?} (known: A, B)", a.layout)
        };
        let foods = a.foods.clone().unwrap_or_else(|| layout.default_foods());
        for &f in &foods {
            if f == 0 || f > layout.ends.len() {
                bail!(
                    "food point {f} does not exist: layout {} has end points 1..={}",
                    layout.name,
                    layout.ends.len()
                );
            }
        }
        if a.trials == 0 {
            bail!("--trials must be at least 1");
        }
        let random_maps = match a.maps {
            Maps::Layout => None,
            Maps::Random if a.count == 0 => bail!("--count must be at least 1"),
            Maps::Random if a.foods.is_some() => {
                bail!(
                    "--foods applies to layouts A and B: each random map draws its own food points"
                )
            }
            Maps::Random => Some(a.count),
        };
        Ok(Options {
            which: a.which,
            trials: a.trials,
            runs: a.runs.max(1),
            out: a.out.clone(),
            seed: a.seed,
            layout,
            foods,
            random_maps,
            progress: !a.quiet,
        })
    }
}

/// What an experiment produced.
pub struct Report {
    pub case1: Option<case1::Case1Result>,
    pub case1_random: Option<random_run::RandomCase1>,
    pub case2: Option<case2::Case2Result>,
    pub files: Vec<PathBuf>,
    pub wall_seconds: f64,
}

/// Runs the chosen case studies (all their trials in parallel on rayon's pool) and writes every file
/// under `opts.out`.
pub fn run(opts: &Options) -> Result<Report> {
    let started = std::time::Instant::now();
    let out = &opts.out;
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let do1 = matches!(opts.which, Which::Case1 | Which::All);
    let do2 = matches!(opts.which, Which::Case2 | Which::All);
    let random = opts.random_maps.filter(|_| do1);
    let do1 = do1 && random.is_none();
    let cfg1 = do1.then(|| {
        let mut c = case1::Case1Config::new(opts.layout.clone(), opts.trials, opts.seed);
        c.foods = opts.foods.clone();
        c
    });
    let cfg2 = if do2 {
        Some(case2::Case2Config::paper(opts.runs, opts.seed)?)
    } else {
        None
    };
    let total = cfg1.as_ref().map_or(0, case1::task_count)
        + cfg2.as_ref().map_or(0, |c| c.runs)
        + random.map_or(0, |n| random_run::task_count(n, opts.trials));
    let bar = super::progress_bar(total as u64, "trials", opts.progress);
    let tick = || bar.inc(1);
    // Both cases share the pool: case II's few long runs start first, case I's trials fill the gaps.
    let (r2, (r1, rr)) = rayon::join(
        || cfg2.as_ref().map(|c| case2::run(c, &tick)).transpose(),
        || {
            let r1 = cfg1.as_ref().map(|c| case1::run(c, &tick)).transpose();
            let forage = toml::Table::new();
            let rr = random
                .map(|n| random_run::run(opts.seed, n, opts.trials, &forage, &tick))
                .transpose();
            (r1, rr)
        },
    );
    bar.finish_and_clear();
    let (r1, r2, rr) = (r1?, r2?, rr?);
    let mut files = Vec::new();
    if let Some(r) = &r1 {
        files.extend(write_case1(r, &out.join("case1"))?);
    }
    if let Some(r) = &r2 {
        files.extend(write_case2(r, &out.join("case2"))?);
    }
    if let Some(r) = &rr {
        files.extend(write_case1_random(r, &out.join("case1_random"))?);
    }
    let wall = started.elapsed().as_secs_f64();
    files.extend(summary::write(out, r1.as_ref(), r2.as_ref(), wall)?);
    if let Some(r) = &rr {
        // The random maps' table also goes into the top-level summary that a reader opens first.
        let md = out.join("summary.md");
        let mut text =
            std::fs::read_to_string(&md).with_context(|| format!("reading {}", md.display()))?;
        text += &format!("\n{}", random_run::markdown(r).replacen("# ", "## ", 1));
        std::fs::write(&md, text).with_context(|| format!("writing {}", md.display()))?;
    }
    Ok(Report {
        case1: r1,
        case1_random: rr,
        case2: r2,
        files,
        wall_seconds: wall,
    })
}

/// `f` of every item in parallel, gathered in the items' order (never by completion order), `tick`
/// called once per finished item for a shared progress count.
fn par_map_ticking<I, R>(
    items: I,
    tick: &(dyn Fn() + Sync),
    f: impl Fn(I::Item) -> R + Sync + Send,
) -> Vec<R>
where
    I: rayon::iter::IntoParallelIterator,
    R: Send,
{
    use rayon::iter::ParallelIterator;
    items
        .into_par_iter()
        .map(|item| {
            let r = f(item);
            tick();
            r
        })
        .collect()
}

/// A CSV writer into memory with its header row written (`\n` line ends, fields quoted only where
/// they must be).
fn csv_writer(header: &[&str]) -> csv::Writer<Vec<u8>> {
    let mut w = csv::WriterBuilder::new()
        .terminator(csv::Terminator::Any(b'\n'))
        .from_writer(Vec::new());
    w.write_record(header).expect("writing to memory");
    w
}

/// The text a [`csv_writer`] holds.
fn csv_text(w: csv::Writer<Vec<u8>>) -> String {
    let bytes = w.into_inner().expect("flushing to memory");
    String::from_utf8(bytes).expect("CSV of UTF-8 fields is UTF-8")
}

/// A directory an experiment writes its files into, and the files written, in order.
struct OutDir {
    dir: PathBuf,
    files: Vec<PathBuf>,
}

impl OutDir {
    fn create(dir: &Path) -> Result<OutDir> {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
        Ok(OutDir {
            dir: dir.to_path_buf(),
            files: Vec::new(),
        })
    }

    /// Writes `text` to the file `name`.
    fn text(&mut self, name: &str, text: String) -> Result<()> {
        let path = self.dir.join(name);
        std::fs::write(&path, text).with_context(|| format!("writing {}", path.display()))?;
        self.files.push(path);
        Ok(())
    }

    /// Has `draw` write the figure `name` (given its path); listed where `draw` says it drew one.
    fn figure_if(&mut self, name: &str, draw: impl FnOnce(&Path) -> Result<bool>) -> Result<()> {
        let path = self.dir.join(name);
        if draw(&path)? {
            self.files.push(path);
        }
        Ok(())
    }

    /// Has `draw` write the figure `name` (given its path).
    fn figure(&mut self, name: &str, draw: impl FnOnce(&Path) -> Result<()>) -> Result<()> {
        self.figure_if(name, |path| draw(path).map(|()| true))
    }
}

fn write_case1(r: &case1::Case1Result, dir: &Path) -> Result<Vec<PathBuf>> {
    let mut out = OutDir::create(dir)?;
    out.text("arrivals.csv", case1::arrivals_csv(r))?;
    out.text("trials.csv", case1::trials_csv(r))?;
    out.figure("fig5_arrivals.png", |p| plots::fig5_arrivals(r, p))?;
    out.figure("fig6_g3_trajectories.png", |p| {
        fig6::fig6_trajectories(r, 2, p)
    })?;
    out.figure("trajectories_all_groups.png", |p| {
        fig6::trajectories_all_groups(r, p)
    })?;
    Ok(out.files)
}

fn write_case1_random(r: &random_run::RandomCase1, dir: &Path) -> Result<Vec<PathBuf>> {
    let mut out = OutDir::create(dir)?;
    out.text("maps.csv", random_run::maps_csv(r))?;
    out.text("summary.md", random_run::markdown(r))?;
    let claims = serde_json::to_string_pretty(&random_run::claims(r))? + "\n";
    out.text("claims.json", claims)?;
    out.figure_if("failures.png", |p| random_plots::failures(r, p, 12))?;
    out.figure("maps.png", |p| random_plots::overview(r, p, 6))?;
    Ok(out.files)
}

fn write_case2(r: &case2::Case2Result, dir: &Path) -> Result<Vec<PathBuf>> {
    let mut out = OutDir::create(dir)?;
    out.text("s_t.csv", case2::s_t_csv(r))?;
    out.figure("fig8_s_t.png", |p| fig78::fig8_s_t(r, p))?;
    out.figure("fig7_snapshots.png", |p| fig78::fig7_snapshots(r, p))?;
    out.figure("trajectories.png", |p| fig78::case2_trajectories(r, p))?;
    Ok(out.files)
}

/// Entry point of the command line: sets up the thread pool, runs, prints where the files are.
pub fn main(args: ExperimentArgs) -> Result<()> {
    crate::cmd::use_threads(args.threads)?;
    let opts = Options::from_args(&args)?;
    let report = run(&opts)?;
    let mut text = summary::console(&report);
    text += &format!("wall time {:.2} s\n", report.wall_seconds);
    for f in &report.files {
        text += &format!("  wrote {}\n", f.display());
    }
    crate::report::print_report(&text)
}
