//! One frame of a scenario as run.gif draws it (screen, obstacle outlines, robots, legend), after a
//! given time, as a PNG: the screenshots in the docs.
//!
//! `cargo run --release -p colcos-sim --example arena_frame -- SCENARIO SECONDS WIDTH OUT.png`
use colcos_sim::output::gif::{frame_height, frame_image};
use colcos_sim::scenario::Scenario;
use colcos_sim::world::World;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [path, seconds, width, out] = args.as_slice() else {
        return Err("usage: arena_frame SCENARIO SECONDS WIDTH OUT.png".into());
    };
    let scenario = Scenario::from_file(path)?;
    let seconds: f32 = seconds.parse()?;
    let width: u32 = width.parse()?;
    let mut world = World::new(&scenario)?;
    let steps = (seconds / scenario.spec.dt).round() as u64;
    for _ in 0..steps {
        world.step();
    }
    let height = frame_height(&scenario.spec.screen, width);
    frame_image(&world, width, height).save(out)?;
    println!("{out}: {width} x {height} after {seconds} s ({steps} steps)");
    Ok(())
}
