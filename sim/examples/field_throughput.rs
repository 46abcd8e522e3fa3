//! Times `GridField::step` for three fields and prints the median milliseconds per step as JSON.
//!
//! ```text
//! cargo run --release -p colcos-sim --example field_throughput -- --nx 640 --ny 480 --steps 50
//! ```
//!
//! Options: `--nx N --ny N --steps N --dt S --scheme auto|explicit|implicit|one_sided
//! --sigma-px P,P,P` (per field: the spread per step, in cells, of the diffusion; the default
//! `35.5,25.5,25.5` with `--diffusion-factor 0.1,0.1,0.5` matches the variance that the ColCOSPhi GUI's
//! Gaussian blur adds per step: `2 d dt / h^2 = factor * sigma^2`) `--r R` (instead: the same
//! `d dt / h^2` for all three fields) `--wind VX,VY` (m/s) `--inject` (deposit a disc per field per step,
//! like the GUI's robots) `--threads N`.
use colcos_sim::Vec2;
use colcos_sim::field::{DiffusionScheme, GridField, GridParams, GridSpec, Kernel};
use std::time::Instant;

fn parse_list(s: &str) -> Vec<f32> {
    s.split(',')
        .map(|v| v.trim().parse().expect("number"))
        .collect()
}

fn main() {
    let mut nx = 640usize;
    let mut ny = 480usize;
    let mut steps = 50usize;
    let mut dt = 0.1f32;
    let mut scheme = DiffusionScheme::Auto;
    let mut sigma = vec![35.5f32, 25.5, 25.5];
    let mut factor = vec![0.1f32, 0.1, 0.5];
    let mut r_all: Option<f32> = None;
    let mut wind = Vec2::ZERO;
    let mut inject = false;
    let mut threads = 0usize;
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        let mut val = || args.next().unwrap_or_else(|| panic!("{a} needs a value"));
        match a.as_str() {
            "--nx" => nx = val().parse().expect("nx"),
            "--ny" => ny = val().parse().expect("ny"),
            "--steps" => steps = val().parse().expect("steps"),
            "--dt" => dt = val().parse().expect("dt"),
            "--scheme" => {
                scheme = match val().as_str() {
                    "auto" => DiffusionScheme::Auto,
                    "explicit" => DiffusionScheme::Explicit,
                    "implicit" => DiffusionScheme::Implicit,
                    "one_sided" => DiffusionScheme::OneSided,
                    s => panic!("unknown scheme {s}"),
                }
            }
            "--sigma-px" => sigma = parse_list(&val()),
            "--diffusion-factor" => factor = parse_list(&val()),
            "--r" => r_all = Some(val().parse().expect("r")),
            "--wind" => {
                let w = parse_list(&val());
                wind = Vec2::new(w[0], w[1]);
            }
            "--inject" => inject = true,
            "--threads" => threads = val().parse().expect("threads"),
            "-h" | "--help" => {
                println!("see the header of sim/examples/field_throughput.rs");
                return;
            }
            other => panic!("unknown option {other}"),
        }
    }
    if threads > 0 {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build_global()
            .expect("rayon pool");
    }
    // Arena 1.4 m wide, as the GUI's.
    let cell = 1.4 / nx as f32;
    let spec = GridSpec { nx, ny, cell };
    let taus = [8.0f32, 200.0, 300.0];
    let mut fields: Vec<GridField> = (0..3)
        .map(|k| {
            // Variance per step per axis 2 r h^2 = factor sigma^2 h^2  =>  r = factor sigma^2 / 2.
            let r = r_all.unwrap_or(factor[k] * sigma[k] * sigma[k] / 2.0);
            let d = r * cell * cell / dt;
            let mut f = GridField::new(
                spec,
                GridParams {
                    evaporation: taus[k],
                    diffusion: d,
                    scheme,
                    wind,
                },
            );
            f.deposit_point(&Kernel::Disc { radius: 0.1 }, Vec2::new(0.7, 0.5), 100.0);
            f
        })
        .collect();
    let radii = [100.0f32, 20.0, 4.0];
    let mut times = Vec::with_capacity(steps);
    for s in 0..steps + 2 {
        let t0 = Instant::now();
        for (k, f) in fields.iter_mut().enumerate() {
            if inject {
                let p = Vec2::new(0.2 + 0.001 * s as f32, 0.3);
                f.deposit_point(
                    &Kernel::Disc {
                        radius: radii[k] * cell,
                    },
                    p,
                    1.0,
                );
            }
            f.step(dt);
        }
        // Two warm-up steps are not counted.
        if s >= 2 {
            times.push(t0.elapsed().as_secs_f64() * 1e3);
        }
    }
    times.sort_by(|a, b| a.total_cmp(b));
    let median = times[times.len() / 2];
    let rs: Vec<String> = (0..3)
        .map(|k| format!("{:.4}", fields[k].params().diffusion * dt / (cell * cell)))
        .collect();
    println!(
        "{{\"nx\": {nx}, \"ny\": {ny}, \"fields\": 3, \"steps\": {steps}, \"dt\": {dt}, \"scheme\": \"{scheme:?}\", \
         \"r\": [{}], \"threads\": {}, \"median_ms\": {median:.4}, \"min_ms\": {:.4}}}",
        rs.join(", "),
        rayon::current_num_threads(),
        times[0]
    );
}
