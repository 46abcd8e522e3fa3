//! The live loop's own work per tick, pose block in to screen frame out: the tracker block parsed,
//! poses set, the fields stepped, pheromone injected, every robot sensed and decided, and the screen
//! rendered at the panel's 4K on the CPU, for 100 robots on the 65-inch panel with three grid
//! pheromones (5 mm cells). Target: at most 5 ms, a quarter of the 20 ms tick. Prints medians of each
//! part and the ratio of the whole to the target.
//!
//! ```text
//! cargo bench -p colcos-bridge --bench live_tick
//! ```
use colcos_bridge::host::Host;
use colcos_bridge::source::frame_to_poses;
use colcos_bridge::swarmcon::{
    FrameTransform, HeaderForm, SlotPose, SlotState, StreamParser, TrackerFrame, write_block,
};
use colcos_sim::scenario::{Scenario, SensorSource};
use std::hint::black_box;
use std::time::Instant;

const SCENARIO: &str = r#"
duration = 10.0
[field]
cell = 0.005
[[pheromones]]
name = "red"
colour = [255, 0, 0]
evaporation = 20.0
diffusion = 1e-6
[[pheromones]]
name = "green"
colour = [0, 255, 0]
evaporation = 20.0
diffusion = 1e-6
[[pheromones]]
name = "blue"
colour = [0, 0, 255]
evaporation = 60.0
maps = [{ polyline = [[0.2, 0.2], [1.2, 0.6]], width = 0.03, rate = 0.05 }]
[[robots]]
count = 100
behaviour = "follow"
params = { channel = "b" }
deposits = [{ pheromone = "red", kernel = { shape = "disc", radius = 0.01 }, rate = 5.0 }]
"#;

fn median(mut xs: Vec<f64>) -> f64 {
    xs.sort_by(f64::total_cmp);
    xs[xs.len() / 2]
}

fn main() {
    let sc = Scenario::from_toml_str(SCENARIO, ".").expect("scenario");
    let mut host = Host::new(&sc, SensorSource::Virtual).expect("host");
    let transform = FrameTransform::new(sc.arena_size().y as f64);
    let start = colcos_sim::world::World::new(&sc)
        .expect("world")
        .poses()
        .to_vec();
    let [w, h] = sc.spec.screen.resolution;
    let (mut parse, mut tick, mut render) = (Vec::new(), Vec::new(), Vec::new());
    let mut parser = StreamParser::new();
    for k in 0..60u64 {
        // A block as the tracker sends it, robots drifting along x.
        let t_us = 1_700_000_000_000_000 + k as i64 * 20_000;
        let robots = start
            .iter()
            .enumerate()
            .map(|(i, p)| {
                let mut p = *p;
                p.pos.x = (p.pos.x + 0.002 * k as f32).min(1.4);
                let (x, y, yaw_deg) = transform.to_tracker(&p);
                SlotPose {
                    id: i as i32,
                    x,
                    y,
                    yaw_deg,
                    last_seen_us: t_us,
                    state: SlotState::Fresh,
                }
            })
            .collect();
        let frame = TrackerFrame {
            t_us,
            found: 100,
            tracked: 100,
            updated: None,
            robots,
        };
        let block = write_block(&frame, HeaderForm::Plain, false);

        let t0 = Instant::now();
        let messages = parser.feed(block.as_bytes());
        let mut poses = Vec::new();
        for m in &messages {
            if let colcos_bridge::swarmcon::TrackerMessage::Frame(f) = m {
                poses = frame_to_poses(f, &transform);
            }
        }
        for p in &poses {
            host.set_pose(p.id as usize, p.pose, host.time());
        }
        let t1 = Instant::now();
        black_box(host.tick(0.02));
        let t2 = Instant::now();
        black_box(host.render(w, h));
        let t3 = Instant::now();
        if k >= 5 {
            parse.push((t1 - t0).as_secs_f64() * 1e3);
            tick.push((t2 - t1).as_secs_f64() * 1e3);
            render.push((t3 - t2).as_secs_f64() * 1e3);
        }
    }
    let total: Vec<f64> = (0..parse.len())
        .map(|i| parse[i] + tick[i] + render[i])
        .collect();
    let (p, t, r, all) = (median(parse), median(tick), median(render), median(total));
    println!("live tick, 100 robots, three 5 mm grids, 65-inch panel (medians of 55 ticks):");
    println!("  parse a 100-robot block and set poses   {p:8.3} ms");
    println!("  fields, injection, sensing, decisions   {t:8.3} ms");
    println!("  screen rendered at {w}x{h} (CPU)      {r:8.3} ms");
    println!(
        "  pose block in to screen frame out       {all:8.3} ms: {:.2}x the 5 ms target ({})",
        5.0 / all,
        if all <= 5.0 { "met" } else { "NOT met" }
    );
}
