//! `[sensor] per_robot = true`: what reading every robot's four sensors through its own models costs.
//! Three colour passes over 150 robots' sensors on the same screen (a deposited trail and a Gaussian
//! source), serial, each timed as the median of 60: the shared model's batched read of a robot's four
//! sensors (the floor), the own models one sensor at a time (four footprint passes per robot), and
//! the own models after one batched footprint pass (what the sense stage does), with a check that
//! the last two give the same readings. Then the median whole world step with and without
//! `per_robot`, the two worlds stepping in turn.
//!
//! cargo bench -p colcos-sim --bench per_robot_sensing
use colcos_sim::field::FrozenSources;
use colcos_sim::rng::{Stream, stream_of};
use colcos_sim::scenario::Scenario;
use colcos_sim::sensors::{
    ColourCalibration, RobotColour, SENSOR_RADIUS, SensorFit, sensor_positions,
};
use colcos_sim::world::World;
use colcos_testkit::scenarios::{SMALL_SCREEN, orange_glow, trail_followers};
use glam::Vec2;
use std::hint::black_box;
use std::time::Instant;

const ROBOTS: usize = 150;
const REPEATS: usize = 60;

/// Every robot its own fitted sensors, gains and curves spread over the robots.
fn calibration() -> ColourCalibration {
    let robots = (0..ROBOTS)
        .map(|i| {
            let f = |k: usize| {
                let x = ((i * 4 + k) % 7) as f64 / 7.0;
                SensorFit::from_parts(
                    2.0 + 0.4 * x,
                    1200.0 + 600.0 * x,
                    [
                        [1.0, 0.05 * x, 0.02],
                        [0.04, 0.95, 0.1 * x],
                        [0.02, 0.08, 1.0],
                    ],
                    [20.0 + 30.0 * x, 30.0, 40.0],
                    24.0,
                )
            };
            RobotColour {
                radio_id: i as u8 + 1,
                sensors: [f(0), f(1), f(2), f(3)],
            }
        })
        .collect();
    ColourCalibration::new("2026-11-24T00:00:00Z".into(), 24.0, robots, 6.0)
}

/// The trail followers on the small screen, with an orange glow besides, reading through `file`
/// (every robot through its own models when `per_robot`).
fn scenario(file: &str, per_robot: bool) -> Scenario {
    trail_followers(ROBOTS)
        .seed(4)
        .screen(SMALL_SCREEN.0, SMALL_SCREEN.1)
        .pheromone(orange_glow(2.0, [0.2, 0.15]))
        .with(|s| {
            s.sensor.per_robot = per_robot;
            s.rig.colour_calibration = Some(file.to_string());
        })
        .build()
        .expect("bench scenario is valid")
}

fn median(mut xs: Vec<f64>) -> f64 {
    xs.sort_by(f64::total_cmp);
    xs[xs.len() / 2]
}

/// Median seconds of `pass` over [`REPEATS`] runs.
fn timed(mut pass: impl FnMut() -> u64) -> f64 {
    let mut check = 0u64;
    let times = (0..REPEATS)
        .map(|_| {
            let t = Instant::now();
            check = check.wrapping_add(pass());
            t.elapsed().as_secs_f64()
        })
        .collect();
    black_box(check);
    median(times)
}

fn main() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("colour.json");
    calibration().save(&path).unwrap();
    let file = path.display().to_string();
    let mut world = World::new(&scenario(&file, true)).unwrap();
    for _ in 0..100 {
        world.step();
    }
    let (pheromones, screen) = (world.pheromones(), world.screen());
    let frozen = FrozenSources::new(pheromones);
    let points: Vec<[Vec2; 4]> = world
        .poses()
        .iter()
        .map(|p| sensor_positions(p, SENSOR_RADIUS))
        .collect();
    let mut rng = stream_of(4, 0, Stream::Telemetry(0));
    let sum = |c: [u16; 3]| c.iter().map(|&v| v as u64).sum::<u64>();

    let shared = world.sensor();
    let floor = timed(|| {
        let mut s = 0;
        for p in &points {
            let c = shared.read_all(pheromones, &frozen, screen, p, &mut rng);
            s += c.into_iter().map(sum).sum::<u64>();
        }
        s
    });
    // Every robot's four readings (counts, intensities) through its own models, both ways.
    type Readings = Vec<[([u16; 3], [f32; 3]); 4]>;
    let one_at_a_time = |rng: &mut colcos_sim::rng::SimRng| -> Readings {
        let own = |i| world.robot_sensors(i).unwrap();
        (0..points.len())
            .map(|i| {
                std::array::from_fn(|k| {
                    let (q, own) = (points[i][k], own(i));
                    let c = own.truth[k].read_all(pheromones, &frozen, screen, &[q], rng);
                    (c[0], own.inverse[k].intensity(c[0]))
                })
            })
            .collect()
    };
    let batched = |rng: &mut colcos_sim::rng::SimRng| -> Readings {
        (0..points.len())
            .map(|i| {
                let own = world.robot_sensors(i).unwrap();
                let sums = own.truth[0].footprint_sums(pheromones, &frozen, screen, &points[i]);
                std::array::from_fn(|k| {
                    let c = own.truth[k].counts_of_sum(sums[k], rng);
                    (c, own.inverse[k].intensity(c))
                })
            })
            .collect()
    };
    let (a, b) = (one_at_a_time(&mut rng.clone()), batched(&mut rng.clone()));
    let differ = a
        .iter()
        .flatten()
        .zip(b.iter().flatten())
        .filter(|(x, y)| x != y)
        .count();
    let digest = |r: Readings| r.iter().flatten().map(|(c, _)| sum(*c)).sum::<u64>();
    let one_at_a_time = timed(|| digest(one_at_a_time(&mut rng)));
    let batched = timed(|| digest(batched(&mut rng)));
    println!(
        "the two ways give the same counts and intensities, noise included, for {} of {} sensors",
        4 * points.len() - differ,
        4 * points.len()
    );
    println!(
        "{ROBOTS} robots x 4 sensors, serial, median of {REPEATS}: shared model {:.1} us; own models one \
         sensor at a time {:.1} us ({:.2}x the shared model); own models after one batched footprint \
         pass {:.1} us ({:.2}x the shared model, {:.2}x faster than one at a time)",
        floor * 1e6,
        one_at_a_time * 1e6,
        one_at_a_time / floor,
        batched * 1e6,
        batched / floor,
        one_at_a_time / batched
    );

    // The two worlds step in turn, so that the machine's load falls on both alike.
    let mut worlds = [false, true].map(|own| World::new(&scenario(&file, own)).unwrap());
    let mut times = [Vec::new(), Vec::new()];
    for k in 0..20 + 2 * REPEATS {
        let t = Instant::now();
        worlds[k % 2].step();
        if k >= 20 {
            times[k % 2].push(t.elapsed().as_secs_f64());
        }
    }
    let [plain, own] = times.map(median);
    println!(
        "world step, {} threads: {:.3} ms with the shared model, {:.3} ms with per_robot ({:.2}x)",
        rayon::current_num_threads(),
        plain * 1e3,
        own * 1e3,
        own / plain
    );
}
