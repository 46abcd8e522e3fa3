//! The live loop's own work per tick, pose block in to screen frame out: the tracker block parsed,
//! poses set, the fields stepped, pheromone injected, every robot sensed and decided, and the screen
//! rendered at the panel's 4K on the CPU, for 100 robots on the 65-inch panel with three grid
//! pheromones (5 mm cells). Target: at most 5 ms, a quarter of the 20 ms tick. Prints medians of each
//! part and of the whole against the 5 ms bar and the 20 ms tick, for the screen drawn three ways in
//! the same run: into a kept image (`ScreenRenderer::render_into`), as a new image (`HostWorld::render`,
//! `screen::render`), and by the per-pixel renderer the simulator had before (`colcos_testkit::screen::reference_render`; every frame is checked to be byte-identical to it).
//!
//! ```text
//! cargo bench -p colcos-bridge --bench live_tick
//! ```
use colcos_bridge::protocol::swarmcon::{
    FrameTransform, HeaderForm, SlotPose, SlotState, StreamParser, TrackerFrame, write_block,
};
use colcos_bridge::rig::HostWorld;
use colcos_bridge::transport::frame_to_poses;
use colcos_sim::scenario::SensorSource;
use colcos_sim::screen::ScreenRenderer;
use colcos_testkit::scenarios::three_grids_panel;
use colcos_testkit::screen::reference_render;
use std::hint::black_box;
use std::time::Instant;

/// The tick's budget and the bar for pose block in to 4K frame out, ms.
const TICK_MS: f64 = 20.0;
const BAR_MS: f64 = 5.0;

fn median(mut xs: Vec<f64>) -> f64 {
    xs.sort_by(f64::total_cmp);
    xs[xs.len() / 2]
}

fn main() {
    let sc = three_grids_panel();
    let mut host = HostWorld::new(&sc, SensorSource::Virtual).expect("host");
    let transform = FrameTransform::new(sc.arena_size().y as f64);
    let start = colcos_sim::world::World::new(&sc)
        .expect("world")
        .poses()
        .to_vec();
    let [w, h] = sc.spec.screen.resolution;
    let screen = *host.screen();
    let mut renderer = ScreenRenderer::new();
    let mut screen_frame = image::RgbImage::new(w, h);
    let (mut parse, mut tick, mut render) = (Vec::new(), Vec::new(), Vec::new());
    let (mut render_new, mut render_old) = (Vec::new(), Vec::new());
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
            if let colcos_bridge::protocol::swarmcon::TrackerMessage::Frame(f) = m {
                poses = frame_to_poses(f, &transform);
            }
        }
        for p in &poses {
            host.set_pose(p.id as usize, p.pose, host.time());
        }
        let t1 = Instant::now();
        black_box(host.tick(0.02));
        let t2 = Instant::now();
        renderer.render_into(host.pheromones(), &screen, &mut screen_frame);
        black_box(&screen_frame);
        let t3 = Instant::now();
        let new_image = black_box(host.render(w, h));
        let t4 = Instant::now();
        let old = black_box(reference_render(
            host.pheromones(),
            &screen,
            w as usize,
            h as usize,
        ));
        let t5 = Instant::now();
        assert!(
            old == *screen_frame.as_raw() && old == *new_image.as_raw(),
            "tick {k}: the frame differs from the reference renderer's"
        );
        if k >= 5 {
            let ms = |a: Instant, b: Instant| (b - a).as_secs_f64() * 1e3;
            parse.push(ms(t0, t1));
            tick.push(ms(t1, t2));
            render.push(ms(t2, t3));
            render_new.push(ms(t3, t4));
            render_old.push(ms(t4, t5));
        }
    }
    let whole = |render: &[f64]| {
        median(
            (0..parse.len())
                .map(|i| parse[i] + tick[i] + render[i])
                .collect(),
        )
    };
    let (all, all_new, all_old) = (whole(&render), whole(&render_new), whole(&render_old));
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    println!(
        "live tick, 100 robots, three 5 mm grids, 65-inch panel, {threads} threads (medians of {} ticks):",
        parse.len()
    );
    println!(
        "  parse a 100-robot block and set poses      {:8.3} ms",
        median(parse.clone())
    );
    println!(
        "  fields, injection, sensing, decisions      {:8.3} ms",
        median(tick.clone())
    );
    println!(
        "  {w}x{h} screen into a kept image        {:8.3} ms",
        median(render)
    );
    println!(
        "  {w}x{h} screen as a new image (Host)    {:8.3} ms",
        median(render_new)
    );
    println!(
        "  {w}x{h} screen, per-pixel reference     {:8.3} ms",
        median(render_old)
    );
    for (what, ms) in [
        ("kept image", all),
        ("new image", all_new),
        ("per-pixel reference", all_old),
    ] {
        println!(
            "  pose block in -> 4K frame out, {what:<20} {ms:8.3} ms: {:5.1}% of the {TICK_MS} ms tick, {:5.2}x the {BAR_MS} ms bar ({})",
            100.0 * ms / TICK_MS,
            ms / BAR_MS,
            if ms <= BAR_MS { "met" } else { "NOT met" }
        );
    }
}
