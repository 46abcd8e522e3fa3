//! One scenario from start to end, writing what a run leaves behind: `scenario.toml`,
//! `trajectory.csv`, `run.gif`, `screen.png`, `fields/<name>.npy` and `summary.json`. A run into a
//! directory that holds an earlier run's files replaces them all.
//!
//! The command line, a sweep runner and the hardware bridge all call [`run`]; what differs between
//! them comes in through [`RunOptions`]: the field backend (the GPU one lives in `colcos-gpu`, which
//! depends on this crate) and a progress callback (the command line draws a bar with it).
mod summary;

use crate::error::SimError;
use crate::field::{BackendChoice, FieldModel, GridSpec};
use crate::output::gif::{self, GifPlan};
use crate::output::{GifRecorder, TrajectoryLog, npy};
use crate::scenario::Scenario;
use crate::screen;
use crate::world::World;
use glam::Vec2;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Installs a field backend in the run's world once it is built (a GPU backend needs the world's
/// pheromones) and describes it for the summary (`gpu: <adapter>`, `cpu (<reason>)`).
pub type BackendSetup<'a> =
    Box<dyn FnOnce(&mut World) -> Result<String, Box<dyn std::error::Error + Send + Sync>> + 'a>;

/// Options of one run beyond the scenario.
#[derive(Default)]
pub struct RunOptions<'a> {
    /// Skip the GIF (runs that only compare logs do not need it).
    pub no_gif: bool,
    /// Sets up the field backend; `None`: the CPU, and an error if the scenario asks for `gpu`.
    pub backend: Option<BackendSetup<'a>>,
    /// Called after every step with (steps done, steps in all).
    pub on_step: Option<&'a mut dyn FnMut(u64, u64)>,
    /// Set (by a signal handler, say) to end the run after the current step; the outputs are written
    /// for what ran, and the report and `summary.json` say it was interrupted.
    pub stop: Option<&'a std::sync::atomic::AtomicBool>,
}

/// What a finished run wrote and how fast it went.
#[derive(Debug, Clone)]
pub struct RunReport {
    pub out_dir: PathBuf,
    pub steps: u64,
    pub robots: usize,
    pub sim_seconds: f32,
    /// Wall time of the steps alone, s.
    pub wall_seconds: f64,
    /// Wall time of the whole run, s: building the world, the steps, the log, the GIF and every
    /// output file (what the user waited for).
    pub total_wall_seconds: f64,
    /// Which ticks the GIF shows (`None`: no GIF written).
    pub gif: Option<GifPlan>,
    pub files: Vec<PathBuf>,
    /// The field backend that stepped the grids (`cpu (...)` or `gpu: <adapter>`).
    pub backend: String,
    /// The run was stopped before the scenario's end (`steps` says how far it got).
    pub interrupted: bool,
}

impl RunReport {
    /// Simulated seconds per wall-clock second (steps only, not the final files).
    pub fn real_time_factor(&self) -> f64 {
        self.sim_seconds as f64 / self.wall_seconds.max(1e-9)
    }

    /// Simulated seconds per wall-clock second of the whole run ([`RunReport::total_wall_seconds`]).
    pub fn overall_real_time_factor(&self) -> f64 {
        self.sim_seconds as f64 / self.total_wall_seconds.max(1e-9)
    }
}

/// Why a run stopped.
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    #[error(transparent)]
    Sim(#[from] SimError),
    /// The field backend the scenario asks for could not be set up.
    #[error("field backend {choice}: {error}")]
    Backend {
        choice: BackendChoice,
        error: Box<dyn std::error::Error + Send + Sync>,
    },
}

/// Runs `scenario` to its end, writing into `out_dir` (created if missing).
pub fn run(
    scenario: &Scenario,
    out_dir: &Path,
    opts: RunOptions<'_>,
) -> Result<RunReport, RunError> {
    let RunOptions {
        no_gif,
        backend,
        mut on_step,
        stop,
    } = opts;
    // What the user waits for: from here to the last file written.
    let started = Instant::now();
    std::fs::create_dir_all(out_dir).map_err(|e| {
        SimError::io(
            format!("creating output directory {}", out_dir.display()),
            e,
        )
    })?;
    clear_previous_outputs(out_dir)?;
    let mut files = Vec::new();
    let scenario_copy = out_dir.join("scenario.toml");
    std::fs::write(&scenario_copy, scenario.to_toml_standalone())
        .map_err(|e| SimError::io(format!("writing {}", scenario_copy.display()), e))?;
    files.push(scenario_copy);

    let mut world = World::new(scenario)?;
    let choice = scenario.spec.field.backend;
    let backend = match backend {
        Some(setup) => setup(&mut world).map_err(|error| RunError::Backend { choice, error })?,
        None => cpu_backend(choice)?,
    };
    log::debug!("field backend: {backend}");
    let log_path = out_dir.join("trajectory.csv");
    let mut log = TrajectoryLog::create(&log_path, &scenario.spec.robots)?;
    files.push(log_path);
    log.record(&world)?;

    let out = &scenario.spec.output;
    let steps = scenario.steps();
    let gif_path = out_dir.join("run.gif");
    let gif_plan = (out.gif_interval > 0.0 && !no_gif).then(|| {
        let height = gif::frame_height(world.screen(), out.gif_width);
        GifPlan::new(
            steps,
            scenario.spec.dt,
            out.gif_interval,
            out.gif_width,
            height,
        )
    });
    let mut gif = match &gif_plan {
        Some(plan) => {
            if plan.thinned > 1 {
                log::info!(
                    "run.gif: a frame every {} s (every {} of `gif_interval`), {} frames in all",
                    plan.interval,
                    plan.thinned,
                    plan.frames
                );
            }
            Some(GifRecorder::create(
                &gif_path,
                &world,
                out.gif_width,
                plan.interval,
            )?)
        }
        None => None,
    };
    let gif_every = gif_plan.map_or(1, |p| p.every);
    if let Some(g) = gif.as_mut() {
        g.frame(&world)?;
        files.push(gif_path);
    }

    let mut stepping = 0.0f64;
    let mut done_steps = 0;
    for done in 1..=steps {
        if stop.is_some_and(|s| s.load(std::sync::atomic::Ordering::Relaxed)) {
            break;
        }
        done_steps = done;
        let t0 = Instant::now();
        world.step();
        stepping += t0.elapsed().as_secs_f64();
        if world.tick() % out.log_every as u64 == 0 {
            log.record(&world)?;
        }
        if let Some(g) = gif.as_mut()
            && world.tick() % gif_every == 0
        {
            g.frame(&world)?;
        }
        if let Some(f) = on_step.as_mut() {
            f(done, steps);
        }
    }
    drop(gif);

    let s = world.screen();
    let (width, height) = png_size(s.resolution);
    let img = screen::render(world.pheromones(), s, width, height);
    let png = out_dir.join("screen.png");
    screen::save_png(&img, &png)?;
    files.push(png);
    files.extend(write_fields(&world, scenario, out_dir)?);

    let mut report = RunReport {
        out_dir: out_dir.to_path_buf(),
        steps: done_steps,
        interrupted: done_steps < steps,
        robots: world.robot_count(),
        sim_seconds: world.time(),
        wall_seconds: stepping,
        total_wall_seconds: 0.0,
        gif: gif_plan,
        files,
        backend,
    };
    let summary = out_dir.join("summary.json");
    report.total_wall_seconds = started.elapsed().as_secs_f64();
    summary::write(&summary, scenario, &report)?;
    report.files.push(summary);
    report.total_wall_seconds = started.elapsed().as_secs_f64();
    Ok(report)
}

/// The backend of a run given none: the CPU, which `cpu` and `auto` accept and `gpu` does not.
fn cpu_backend(choice: BackendChoice) -> Result<String, RunError> {
    match choice {
        BackendChoice::Cpu => Ok("cpu (asked for)".into()),
        BackendChoice::Auto => Ok("cpu (auto: no GPU backend given to this run)".into()),
        BackendChoice::Gpu => Err(RunError::Backend {
            choice,
            error: "no GPU backend given to this run".into(),
        }),
    }
}

/// One `.npy` per pheromone, shape (ny, nx), row 0 at y = 0: grid fields as they are, Gaussian fields
/// evaluated at the centres of the scenario's field grid.
/// Removes what an earlier run wrote into `out_dir` (its files only, nothing else there), so that a
/// run into the same directory replaces them all and never leaves a mix of two runs.
fn clear_previous_outputs(out_dir: &Path) -> Result<(), SimError> {
    let remove = |path: PathBuf| match std::fs::remove_file(&path) {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => Err(SimError::io(
            format!("removing the earlier run's {}", path.display()),
            e,
        )),
        _ => Ok(()),
    };
    for name in [
        "scenario.toml",
        "trajectory.csv",
        "run.gif",
        "screen.png",
        "summary.json",
    ] {
        remove(out_dir.join(name))?;
    }
    if let Ok(entries) = std::fs::read_dir(out_dir.join("fields")) {
        for entry in entries.flatten() {
            let path = entry.path();
            if path.extension().is_some_and(|e| e == "npy") {
                remove(path)?;
            }
        }
    }
    Ok(())
}

fn write_fields(
    world: &World,
    scenario: &Scenario,
    out_dir: &Path,
) -> Result<Vec<PathBuf>, SimError> {
    let dir = out_dir.join("fields");
    std::fs::create_dir_all(&dir)
        .map_err(|e| SimError::io(format!("creating {}", dir.display()), e))?;
    let mut files = Vec::new();
    for p in world.pheromones() {
        let path = dir.join(format!("{}.npy", crate::output::file_safe(&p.name, &[])));
        match &p.model {
            FieldModel::Grid(g) => {
                npy::write_npy_f32(&path, &[g.spec().ny, g.spec().nx], g.values())?
            }
            FieldModel::Gaussian(g) => {
                let spec = GridSpec::covering(world.arena(), scenario.spec.field.cell);
                let values: Vec<f32> = (0..spec.ny)
                    .flat_map(|j| (0..spec.nx).map(move |i| (i, j)))
                    .map(|(i, j)| {
                        g.value_at(Vec2::new(
                            (i as f32 + 0.5) * spec.cell,
                            (j as f32 + 0.5) * spec.cell,
                        ))
                    })
                    .collect();
                npy::write_npy_f32(&path, &[spec.ny, spec.nx], &values)?
            }
        }
        files.push(path);
    }
    Ok(files)
}

/// Largest final screen image written, in pixels: an 8K panel. A virtual screen beyond it (the
/// 10,000-robot benchmark's arena is 38,400 x 21,600 pixels, 2.5 GB as RGB) is drawn scaled down to fit,
/// with its aspect ratio.
const MAX_PNG_PIXELS: u64 = 7680 * 4320;

/// The size of `screen.png` for a panel of `resolution` pixels: the panel's own, or scaled down to at
/// most [`MAX_PNG_PIXELS`].
fn png_size(resolution: [u32; 2]) -> (u32, u32) {
    let [w, h] = resolution.map(|r| r.max(1));
    let pixels = u64::from(w) * u64::from(h);
    if pixels <= MAX_PNG_PIXELS {
        return (w, h);
    }
    let scale = (MAX_PNG_PIXELS as f64 / pixels as f64).sqrt();
    let fit = |n: u32| ((f64::from(n) * scale).floor() as u32).max(1);
    (fit(w), fit(h))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn screen_png_keeps_panels_up_to_8k_and_scales_larger_ones() {
        assert_eq!(png_size([3840, 2160]), (3840, 2160));
        assert_eq!(png_size([7680, 4320]), (7680, 4320));
        assert_eq!(png_size([38_400, 21_600]), (7680, 4320));
        let (w, h) = png_size([65_536, 100]);
        assert!(
            u64::from(w) * u64::from(h) <= MAX_PNG_PIXELS && h >= 1,
            "{w} x {h}"
        );
    }

    /// The `scenario.toml` a run saves loads again from its output directory: relative image paths
    /// are written absolute.
    #[test]
    fn the_saved_scenario_runs_again_from_the_output_directory() {
        let src = tempfile::tempdir().unwrap();
        std::fs::create_dir(src.path().join("maps")).unwrap();
        image::RgbImage::from_pixel(8, 6, image::Rgb([0, 0, 200]))
            .save(src.path().join("maps/loop.png"))
            .unwrap();
        // A relative image path, resolved against the scenario's directory.
        let sc = crate::scenario::ScenarioBuilder::new()
            .duration(0.04)
            .gif_interval(0.0)
            .base_dir(src.path())
            .pheromone(
                crate::scenario::PheromoneSpec::grid("trail", [0.0, 0.0, 255.0])
                    .with_evaporation(10.0)
                    .with_map(crate::scenario::MapSpec::Image {
                        image: "maps/loop.png".into(),
                        channel: Some(crate::channel::ImageChannel::B),
                        rate: 1.0,
                    }),
            )
            .robots(crate::scenario::RobotGroupSpec::new(2, "avoid"))
            .build()
            .unwrap();
        let out = tempfile::tempdir().unwrap();
        run(&sc, out.path(), RunOptions::default()).unwrap();
        let saved = Scenario::from_file(out.path().join("scenario.toml")).expect("the saved copy");
        let crate::scenario::MapSpec::Image { image, .. } = &saved.spec.pheromones[0].maps[0]
        else {
            panic!("an image map")
        };
        assert!(Path::new(&image).is_absolute(), "{image}");
        let again = tempfile::tempdir().unwrap();
        let report = run(&saved, again.path(), RunOptions::default()).expect("runs again");
        assert_eq!(report.steps, 2);
        assert_eq!(
            std::fs::read(out.path().join("trajectory.csv")).unwrap(),
            std::fs::read(again.path().join("trajectory.csv")).unwrap()
        );
    }

    /// A run longer than the GIF's frame limit gets a frame every few intervals, and says so.
    #[test]
    fn a_long_runs_gif_is_thinned_to_the_frame_limit() {
        use image::AnimationDecoder;
        let text = "duration = 25.0\n[screen]\nsize = [0.3, 0.2]\nresolution = [300, 200]\n\
                    [field]\ncell = 0.02\n[output]\ngif_interval = 0.02\ngif_width = 30\n\
                    [[robots]]\ncount = 2\nbehaviour = \"avoid\"\n";
        let sc = Scenario::from_toml_str(text, ".").unwrap();
        let out = tempfile::tempdir().unwrap();
        let report = run(&sc, out.path(), RunOptions::default()).unwrap();
        // 1,251 frames wanted (one a tick): every second tick fits the 1,000 frame limit.
        let plan = report.gif.unwrap();
        assert_eq!((plan.every, plan.thinned, plan.frames), (2, 2, 626));
        let file = std::fs::File::open(out.path().join("run.gif")).unwrap();
        let frames = image::codecs::gif::GifDecoder::new(std::io::BufReader::new(file))
            .unwrap()
            .into_frames()
            .collect_frames()
            .unwrap();
        assert_eq!(frames.len() as u64, plan.frames);
        // Each frame is shown for the two ticks it stands for: the GIF plays in real time.
        let (n, d) = frames[1].delay().numer_denom_ms();
        assert_eq!(n / d, 40);
        let summary = std::fs::read_to_string(out.path().join("summary.json")).unwrap();
        assert!(summary.contains("\"gif_interval\": 0.04,"), "{summary}");
        assert!(summary.contains("\"gif_thinned\": 2,"), "{summary}");
        assert!(report.total_wall_seconds >= report.wall_seconds);
    }

    #[test]
    fn without_a_backend_gpu_is_refused_and_auto_takes_the_cpu() {
        assert!(cpu_backend(BackendChoice::Cpu).is_ok());
        assert!(cpu_backend(BackendChoice::Auto).unwrap().starts_with("cpu"));
        let e = cpu_backend(BackendChoice::Gpu).unwrap_err().to_string();
        assert!(e.starts_with("field backend gpu: "), "{e}");
    }
}
