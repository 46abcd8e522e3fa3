//! `colcos replay`: a rig log put through the live loop again. The loop is a function of the poses,
//! telemetry, tick times and watchdog stops it took, so the same inputs must give the same command
//! bytes; this checks that a recorded run is reproducible (and what changed when it is not).
use anyhow::{Context, Result, bail};
use clap::Args;
use colcos_bridge::protocol::colias::LegacyDrive;
use colcos_bridge::rig::{LoopCore, replay};
use colcos_sim::scenario::Scenario;
use std::fmt::Write as _;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct ReplayArgs {
    /// The scenario the run was made with (its behaviours, fields and `[rig]` section).
    pub scenario: PathBuf,
    /// The run's rig log (`rig.mcap` from `colcos bridge --out DIR`).
    pub log: PathBuf,
}

pub fn run(args: ReplayArgs, text: &mut String) -> Result<()> {
    let sc = Scenario::from_file(&args.scenario)?;
    let bytes =
        std::fs::read(&args.log).with_context(|| format!("reading {}", args.log.display()))?;
    let ticks = replay::read_ticks(&bytes, sc.robot_count())
        .with_context(|| format!("{}", args.log.display()))?;
    let mut core = LoopCore::new(&sc, LegacyDrive::default())?;
    let report = replay::replay(&mut core, &ticks);
    writeln!(
        text,
        "replayed {} ticks ({:.1} s) of {}: {} command frames, {} ticks differ",
        report.ticks,
        ticks.last().map_or(0.0, |t| t.t),
        args.log.display(),
        report.frames,
        report.mismatched_ticks
    )?;
    if let Some(first) = report.first_mismatch {
        bail!(
            "{} of {} ticks sent other command bytes than the recording, the first at tick {first}: \
             the scenario differs from the run's, or the run was made by another colcos",
            report.mismatched_ticks,
            report.ticks
        );
    }
    writeln!(text, "the same inputs gave the same command bytes")?;
    Ok(())
}
