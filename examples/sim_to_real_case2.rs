//! Case II (aggregation interrupted by the alarm pheromone) three ways: (a) pure simulation, (b) on a
//! digital twin whose tracker is `TWIN_LATENCY` s late while the host compensates nothing
//! (`[rig] latency = 0`, as the paper's rig), (c) the same twin with `[rig] latency` set to the lag
//! measured in (b). Writes S(t) of every curve and one summary line each: mean S, and the mean
//! distance between where the host injects (the pose it uses) and the robot's true pose on the twin.
//!
//! `cargo run --release --example sim_to_real_case2 -- OUT_DIR [SECONDS]` (default 60 s per run, in
//! real time: a run on the twin takes as long as it simulates) writes `s_t.csv`, `summary.txt` and
//! the figure `s_t.png`; `-- --plot OUT_DIR` draws the figure again from `s_t.csv`.
use colcos::bridge::calibrate::RigCalibration;
use colcos::bridge::protocol::swarmcon::HeaderForm;
use colcos::bridge::rig::{LiveOptions, LiveSession, RigEnds};
use colcos::bridge::twin::{TrackerServer, Twin, UdpChannel};
use colcos::bridge::{SourceOptions, open_pose_source, open_robot_link};
use colcos::experiment::case2::SCENARIO_TOML;
use colcos::sim::metrics::sum_distance_of;
use colcos::sim::prelude::*;
use std::fmt::Write as _;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// The paper's rig: its tracker delivers poses 100-150 ms after they were taken.
const TWIN_LATENCY: f32 = 0.12;
/// S(t) and the distances are sampled this often, s.
const SAMPLE: f32 = 0.5;

struct Curve {
    label: String,
    times: Vec<f32>,
    s: Vec<f32>,
    /// Per tick: mean distance between injection pose and true pose, m (empty in simulation).
    miss: Vec<f32>,
    /// Host pose at tick k beside the true poses (for the lag estimate).
    host: Vec<Vec<Vec2>>,
    truth: Vec<Vec<Vec2>>,
}

fn roles(world: &World) -> (usize, Vec<usize>) {
    let n = world.robot_count();
    let leader = (0..n)
        .find(|&i| world.role(i) == "leader")
        .expect("a leader");
    let followers = (0..n).filter(|&i| world.role(i) == "follower").collect();
    (leader, followers)
}

fn simulate(scenario: &Scenario) -> Curve {
    let mut world = World::with_index(scenario, 0).expect("world");
    let (leader, followers) = roles(&world);
    let every = (SAMPLE / world.dt()).round() as u64;
    let mut c = Curve::new("simulation");
    while !world.is_finished() {
        world.step();
        if world.tick().is_multiple_of(every) {
            let pos: Vec<Vec2> = world.poses().iter().map(|p| p.pos).collect();
            c.times.push(world.time());
            c.s.push(sum_distance_of(&pos, leader, &followers));
        }
    }
    c
}

impl Curve {
    fn new(label: &str) -> Curve {
        Curve {
            label: label.into(),
            times: Vec::new(),
            s: Vec::new(),
            miss: Vec::new(),
            host: Vec::new(),
            truth: Vec::new(),
        }
    }
    fn mean(v: &[f32]) -> f32 {
        v.iter().sum::<f32>() / v.len().max(1) as f32
    }
    /// The lag (ticks) at which the host's poses best match the true ones shifted back.
    fn best_lag(&self) -> usize {
        let err = |lag: usize| {
            let pairs = self.host.iter().skip(lag).zip(&self.truth);
            let (mut sum, mut k) = (0.0, 0);
            for (h, t) in pairs {
                sum += h.iter().zip(t).map(|(a, b)| a.distance(*b)).sum::<f32>();
                k += 1;
            }
            sum / k.max(1) as f32
        };
        (0..40)
            .min_by(|&a, &b| err(a).total_cmp(&err(b)))
            .unwrap_or(0)
    }
}

/// One live run of `host` against a twin playing `twin`, in real time.
fn on_twin(label: &str, host: &Scenario, twin: &Scenario) -> Curve {
    let tracker = TrackerServer::bind("127.0.0.1:0", HeaderForm::Updated).expect("tracker");
    let channel = UdpChannel::bind("127.0.0.1:0").expect("link");
    let tracker_url = format!("swarmcon://{}", tracker.local_addr());
    let robots_url = format!("udp://{}", channel.local_addr().expect("link"));
    let twin = Arc::new(Mutex::new(
        Twin::new(twin, tracker, Box::new(channel), None).expect("twin"),
    ));
    let stop = Arc::new(AtomicBool::new(false));
    // The twin ticks on its own thread, locked only for a tick, so its true poses can be read here.
    let ticker = {
        let (twin, stop) = (twin.clone(), stop.clone());
        let dt = Duration::from_secs_f32(host.spec.dt);
        std::thread::spawn(move || {
            let mut next = Instant::now();
            while !stop.load(Ordering::Relaxed) {
                twin.lock().unwrap().tick();
                next += dt;
                std::thread::sleep(next.saturating_duration_since(Instant::now()));
            }
        })
    };
    let cal = RigCalibration::load(host).expect("calibration");
    let source = open_pose_source(&tracker_url, &SourceOptions::new(cal.frame_transform(host)))
        .expect("pose source");
    let link = open_robot_link(&robots_url).expect("robot link");
    let ends = RigEnds {
        source,
        link,
        frames: None,
    };
    let mut session = LiveSession::new(host, ends, LiveOptions::default()).expect("session");
    let probe = World::new(host).expect("world");
    let (leader, followers) = roles(&probe);
    let n = probe.robot_count();
    let overrides = vec![None; n];
    let ticks = host.steps();
    let every = (SAMPLE / host.spec.dt).round() as u64;
    let mut c = Curve::new(label);
    for k in 1..=ticks {
        session.wait_next();
        session.tick(&overrides).expect("tick");
        let used: Vec<Vec2> = session
            .core()
            .host()
            .poses()
            .iter()
            .map(|p| p.pos)
            .collect();
        let truth: Vec<Vec2> = twin
            .lock()
            .unwrap()
            .arena()
            .world()
            .poses()
            .iter()
            .map(|p| p.pos)
            .collect();
        let miss = used
            .iter()
            .zip(&truth)
            .map(|(a, b)| a.distance(*b))
            .sum::<f32>()
            / n as f32;
        c.miss.push(miss);
        if k % every == 0 {
            c.times.push(k as f32 * host.spec.dt);
            c.s.push(sum_distance_of(&truth, leader, &followers));
        }
        c.host.push(used);
        c.truth.push(truth);
    }
    drop(session);
    stop.store(true, Ordering::Relaxed);
    let _ = ticker.join();
    c
}

/// The S(t) curves (label, points) in one chart, in the style of the case II figures.
fn plot(curves: &[(String, Vec<(f64, f64)>)], title: &str, path: &std::path::Path) {
    use colcos::experiment::plots::{ensure_font, series_legend};
    use plotters::prelude::*;
    ensure_font();
    let (w, h) = (1200u32, 600u32);
    let mut buf = vec![255u8; (w * h * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
        root.fill(&WHITE).expect("fill");
        let pts = curves.iter().flat_map(|c| c.1.iter());
        let (tmax, smax) = pts.fold((1.0f64, 0.1f64), |(a, b), p| (a.max(p.0), b.max(p.1)));
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 22))
            .margin(15)
            .x_label_area_size(45)
            .y_label_area_size(60)
            .build_cartesian_2d(0f64..tmax, 0f64..smax * 1.3)
            .expect("chart");
        chart
            .configure_mesh()
            .x_desc("time (s)")
            .y_desc("S (m)")
            .label_style(("sans-serif", 16))
            .axis_desc_style(("sans-serif", 18))
            .light_line_style(TRANSPARENT)
            .draw()
            .expect("mesh");
        let colours = [BLACK, RGBColor(220, 60, 40), RGBColor(30, 110, 220)];
        for ((label, points), colour) in curves.iter().zip(colours.iter().cycle()) {
            let c = *colour;
            chart
                .draw_series(LineSeries::new(points.iter().copied(), c.stroke_width(3)))
                .expect("series")
                .label(label)
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(3))
                });
        }
        series_legend(&mut chart).expect("legend");
        root.present().expect("present");
    }
    let img = image::RgbImage::from_raw(w, h, buf).expect("image");
    colcos::sim::screen::save_png(&img, path).expect("png");
}

/// The curves of an `s_t.csv`, in the order they first appear.
fn read_csv(path: &std::path::Path) -> Vec<(String, Vec<(f64, f64)>)> {
    let text = std::fs::read_to_string(path).expect("s_t.csv");
    let mut curves: Vec<(String, Vec<(f64, f64)>)> = Vec::new();
    for line in text.lines().skip(1) {
        let mut f = line.rsplitn(3, ',');
        let (Some(s), Some(t), Some(label)) = (f.next(), f.next(), f.next()) else {
            continue;
        };
        let p = (t.parse().unwrap_or(0.0), s.parse().unwrap_or(0.0));
        match curves.iter_mut().find(|c| c.0 == label) {
            Some(c) => c.1.push(p),
            None => curves.push((label.to_string(), vec![p])),
        }
    }
    curves
}

const TITLE: &str =
    "Case II S(t): simulation, twin with a late tracker, twin with latency compensation";

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.get(1).is_some_and(|a| a == "--plot") {
        let dir = std::path::PathBuf::from(args.get(2).expect("--plot OUT_DIR"));
        plot(&read_csv(&dir.join("s_t.csv")), TITLE, &dir.join("s_t.png"));
        return;
    }
    let out = std::path::PathBuf::from(args.get(1).map_or("sim_to_real", |s| s.as_str()));
    let seconds: f32 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(60.0);
    std::fs::create_dir_all(&out).expect("output directory");
    let base = Scenario::from_toml_str(SCENARIO_TOML, ".")
        .and_then(|s| s.with_overrides(Some(1), Some(seconds)))
        .expect("case II scenario");
    let mut twin = base.clone();
    twin.spec.tracker.latency = TWIN_LATENCY;
    let sim = simulate(&base);
    let raw = on_twin("twin, no compensation", &base, &twin);
    let lag = raw.best_lag() as f32 * base.spec.dt;
    let mut compensated = base.clone();
    compensated.spec.rig.latency = lag;
    let comp = on_twin(
        &format!("twin, [rig] latency = {lag:.2} s"),
        &compensated,
        &twin,
    );
    let mut csv = String::from("curve,t,S\n");
    let mut summary = format!(
        "case II, {seconds} s per run, twin tracker latency {TWIN_LATENCY} s, lag measured in run b: {lag:.2} s\n"
    );
    for c in [&sim, &raw, &comp] {
        for (t, s) in c.times.iter().zip(&c.s) {
            let _ = writeln!(csv, "{},{t},{s}", c.label);
        }
        let miss = if c.miss.is_empty() {
            "-".to_string()
        } else {
            format!("{:.1} mm", 1000.0 * Curve::mean(&c.miss))
        };
        let _ = writeln!(
            summary,
            "{:<34} mean S {:.3} m   mean injection-to-true distance {miss}",
            c.label,
            Curve::mean(&c.s)
        );
    }
    std::fs::write(out.join("s_t.csv"), csv).expect("s_t.csv");
    std::fs::write(out.join("summary.txt"), &summary).expect("summary.txt");
    plot(&read_csv(&out.join("s_t.csv")), TITLE, &out.join("s_t.png"));
    print!("{summary}");
}
