//! `colcos rig check`: the pre-flight check of a scenario's behaviours on a digital twin started here,
//! before they drive the real robots.
use anyhow::{Result, bail};
use clap::{Args, Subcommand};
use colcos_plant::preflight::{self, PreflightLimits};
use colcos_sim::scenario::Scenario;
use std::fmt::Write as _;
use std::path::PathBuf;

#[derive(Subcommand, Debug)]
pub enum RigCommand {
    /// Run the scenario's behaviours on a digital twin for a few episodes and refuse (exit status 1,
    /// every limit broken named) when the shield stepped in too often, a robot reached the arena's
    /// edge, robots collided or the loop overran its ticks.
    Check(CheckArgs),
    /// Drive a short, bounded excitation (held wheel commands of random length, inside the shield)
    /// while the bridge records the rig log that `colcos rig identify` fits.
    Excite(super::identify::ExciteArgs),
    /// Fit each robot's wheel scales, motor lag and command latency from a rig log, each with its
    /// uncertainty, into a file of per-robot values for `[individual] file`.
    Identify(super::identify::IdentifyArgs),
}

#[derive(Args, Debug)]
pub struct CheckArgs {
    /// Scenario file (TOML) with its `[rig]` section and calibrations.
    pub scenario: PathBuf,
    /// Episodes (seeds: the scenario's, then the next ones).
    #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u64).range(1..=100))]
    pub episodes: u64,
    /// Seconds each episode runs (in real time).
    #[arg(long, default_value_t = 20.0)]
    pub seconds: f64,
    /// Largest fraction of robot-ticks the shield may turn from a virtual wall.
    #[arg(long, default_value_t = 0.05)]
    pub max_walled: f64,
    /// Largest fraction of robot-ticks whose wheel speeds the shield may cap.
    #[arg(long, default_value_t = 0.05)]
    pub max_capped: f64,
    /// Largest number of ticks with a robot's body past the arena's edge by more than
    /// --edge-tolerance.
    #[arg(long, default_value_t = 0)]
    pub max_boundary: u64,
    /// How far a body may reach past the edge before the tick counts, m [default: the tracker's
    /// noise: 3 mm or five standard deviations of `[tracker] position_noise`, whichever is larger].
    #[arg(long)]
    pub edge_tolerance: Option<f32>,
    /// Largest fraction of ticks with two robots overlapping by more than 5 mm.
    #[arg(long, default_value_t = 0.02)]
    pub max_collisions: f64,
    /// Largest fraction of ticks that overran their slot.
    #[arg(long, default_value_t = 0.02)]
    pub max_overruns: f64,
}

pub fn run(command: RigCommand, text: &mut String) -> Result<()> {
    let args = match command {
        RigCommand::Check(args) => args,
        RigCommand::Excite(args) => return super::identify::excite(args, text),
        RigCommand::Identify(args) => return super::identify::identify(args, text),
    };
    if !(args.seconds.is_finite() && args.seconds > 0.0 && args.seconds <= 3600.0) {
        bail!("--seconds {}: must be in (0, 3600]", args.seconds);
    }
    for (name, v) in [
        ("--max-walled", args.max_walled),
        ("--max-capped", args.max_capped),
        ("--max-collisions", args.max_collisions),
        ("--max-overruns", args.max_overruns),
    ] {
        if !(0.0..=1.0).contains(&v) {
            bail!("{name} {v}: must be a fraction in [0, 1]");
        }
    }
    if let Some(t) = args.edge_tolerance
        && !(t.is_finite() && (0.0..=0.05).contains(&t))
    {
        bail!("--edge-tolerance {t}: must be in [0, 0.05] m");
    }
    let sc = Scenario::from_file(&args.scenario)?;
    let limits = PreflightLimits {
        walled: args.max_walled,
        capped: args.max_capped,
        boundary: args.max_boundary,
        edge_tolerance: args.edge_tolerance,
        collisions: args.max_collisions,
        overruns: args.max_overruns,
    };
    let r = preflight::check(&sc, args.episodes as usize, args.seconds, &limits)?;
    let c = &r.counts;
    writeln!(
        text,
        "pre-flight of {} on the twin: {} episodes, {} ticks; walled {}, capped {} of {} robot-ticks; \
         {} ticks past the edge, {} with robots overlapping, {} overruns; safety stops: {}",
        args.scenario.display(),
        r.episodes,
        c.ticks,
        c.walled,
        c.capped,
        c.robot_ticks,
        c.boundary,
        c.collisions,
        c.overruns,
        if r.stops.is_empty() {
            "none".to_string()
        } else {
            r.stops.join(", ")
        }
    )?;
    if !r.broken.is_empty() {
        bail!("pre-flight refused: {}", r.broken.join("; "));
    }
    writeln!(text, "pre-flight passed: the behaviours may drive the rig")?;
    Ok(())
}
