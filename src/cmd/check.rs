//! `colcos check`: a scenario file checked as `colcos run` and the bridge would check it, and what it
//! sets up, without running it.
use anyhow::{Context, Result};
use colcos_sim::scenario::Scenario;
use std::fmt::Write as _;
use std::path::Path;

pub fn main(scenario: &Path, text: &mut String) -> Result<()> {
    let sc = Scenario::from_file(scenario)?;
    // What the bridge would refuse as it starts: calibration files that cannot be used.
    colcos_bridge::calibrate::RigCalibration::load(&sc)
        .with_context(|| format!("{}", scenario.display()))?;
    let a = sc.arena_size();
    writeln!(text, "{}: ok", scenario.display())?;
    writeln!(
        text,
        "  arena {} x {} m, {} s at dt {} s ({} steps), seed {}",
        a.x,
        a.y,
        sc.spec.duration,
        sc.spec.dt,
        sc.steps(),
        sc.spec.seed
    )?;
    let pheromones = sc.spec.pheromones.iter().map(|p| {
        let (name, model, colour) = (&p.name, &p.model, p.colour);
        format!("pheromone {name:?}: {model:?} model, colour {colour:?}")
    });
    let groups = sc.spec.robots.iter().map(|g| {
        let (count, role, behaviour) = (g.count, &g.role, &g.behaviour);
        format!("{count} robot(s), role {role:?}, behaviour {behaviour:?}")
    });
    for line in pheromones.chain(groups) {
        writeln!(text, "  {line}")?;
    }
    Ok(())
}
