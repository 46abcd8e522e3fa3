//! The `[individual]` section: robots that differ. Real Colias robots are not the simulator's one
//! model: a wheel runs slower than its twin, a motor answers late, a radio delivers commands a few
//! steps late, a sensor reads high. Each entry gives one robot (by its index in the scenario's order)
//! its own wheel-speed scales, motor lag, command latency and sensor gain and offset; robots without
//! an entry, and keys an entry leaves out, keep the nominal values (`[robot]`, `[sensor]`).
//!
//! ```toml
//! [individual]
//! file = "fit.toml"          # entries from a file (`[[robot]]` tables), e.g. `colcos rig identify`'s
//! [[individual.robot]]       # inline entries, over the file's for the same robot
//! index = 0
//! wheel_scale = [1.0, 0.9]   # left, right: the wheel's speed per unit of command
//! motor_lag = 0.08           # s, replaces [robot] motor_lag for this robot
//! latency = 0.04             # s from command to the wheels, rounded to whole steps
//! sensor_gain = 0.8          # factor on every colour count
//! sensor_offset = 120.0      # counts added to every colour count
//! ```
use crate::error::{Result, SimError};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// Largest command latency, s (the tracker's bound: beyond it nothing could be controlled).
pub const MAX_COMMAND_LATENCY: f32 = 1.0;

#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct IndividualSpec {
    /// A file of `[[robot]]` entries, relative to the scenario file.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub file: Option<String>,
    /// Inline entries; one for a robot the file also lists replaces the file's keys it sets.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub robot: Vec<RobotIndividual>,
}

impl IndividualSpec {
    pub fn is_default(&self) -> bool {
        *self == IndividualSpec::default()
    }
}

/// One robot's own values; absent keys keep the nominal ones. The `*_sd` keys are uncertainties (one
/// standard deviation) that `colcos rig identify` writes beside its estimates; the simulator ignores
/// them.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RobotIndividual {
    /// The robot's index in the scenario's order (groups in order, robots in each group).
    pub index: usize,
    /// Left and right wheel speed per unit of command (1: as commanded).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub wheel_scale: Option<[f32; 2]>,
    /// First-order motor time constant, s.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub motor_lag: Option<f32>,
    /// Time from a command to the wheels taking it, s; the simulator rounds it to whole steps.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub latency: Option<f32>,
    /// Factor on every colour count this robot reads.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sensor_gain: Option<f32>,
    /// Counts added to every colour count this robot reads (after the gain).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sensor_offset: Option<f32>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub wheel_scale_sd: Option<[f32; 2]>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub motor_lag_sd: Option<f32>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub latency_sd: Option<f32>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sensor_gain_sd: Option<f32>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sensor_offset_sd: Option<f32>,
}

/// A file of per-robot values (`[[robot]]` entries): what `[individual] file`, `colcos twin --truth`
/// and `colcos rig identify --out` read and write. `[identified]` carries free notes (the log fitted,
/// the scenario) that the simulator does not read.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct IndividualFile {
    #[serde(skip_serializing_if = "Option::is_none")]
    pub identified: Option<toml::Table>,
    pub robot: Vec<RobotIndividual>,
}

impl IndividualFile {
    /// Reads and parses `path`; errors name the file and the key.
    pub fn load(path: &Path) -> Result<IndividualFile> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| SimError::io(format!("reading per-robot values {}", path.display()), e))?;
        Self::parse(&text).map_err(|message| SimError::Parse {
            path: path.display().to_string(),
            message,
        })
    }

    /// Parses the file's text; the error names the key that is wrong.
    pub fn parse(text: &str) -> std::result::Result<IndividualFile, String> {
        let de = toml::de::Deserializer::parse(text).map_err(|e| e.to_string())?;
        let file: IndividualFile = serde_path_to_error::deserialize(de).map_err(|e| {
            let path = e.path().to_string();
            format!("at `{path}`: {}", e.into_inner())
        })?;
        // Serde fills `[left, right]` from the first two values of a longer array and drops the
        // rest: a third wheel must be refused, not ignored.
        let table: toml::Table = text.parse().map_err(|e: toml::de::Error| e.to_string())?;
        let entries = table.get("robot").and_then(|r| r.as_array());
        for (n, entry) in entries.into_iter().flatten().enumerate() {
            for key in ["wheel_scale", "wheel_scale_sd"] {
                if let Some(a) = entry.get(key).and_then(|v| v.as_array())
                    && a.len() != 2
                {
                    return Err(format!(
                        "at `robot[{n}].{key}`: expected 2 values (left, right), got {}",
                        a.len()
                    ));
                }
            }
        }
        Ok(file)
    }

    pub fn to_toml(&self) -> String {
        toml::to_string_pretty(self).unwrap_or_default()
    }

    /// Every robot's values from this file's entries alone (a robot it leaves out: nominal), checked
    /// for a scenario of `robots` robots (errors name the entry as `robot[n].field`).
    pub fn resolve(&self, robots: usize) -> Result<Vec<Individual>> {
        validate_entries(&self.robot, "robot", robots)?;
        let mut out = vec![Individual::default(); robots];
        for e in &self.robot {
            out[e.index].overlay(e);
        }
        Ok(out)
    }
}

/// One robot's resolved values: what the world builds its actuation and sensing from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Individual {
    pub wheel_scale: [f32; 2],
    /// `None`: `[robot] motor_lag` (as drawn by `[randomize]`).
    pub motor_lag: Option<f32>,
    /// s.
    pub latency: f32,
    pub sensor_gain: f32,
    pub sensor_offset: f32,
}

impl Default for Individual {
    fn default() -> Self {
        Individual {
            wheel_scale: [1.0, 1.0],
            motor_lag: None,
            latency: 0.0,
            sensor_gain: 1.0,
            sensor_offset: 0.0,
        }
    }
}

impl Individual {
    /// Whether the robot drives as the nominal model does (no per-robot actuation needed).
    pub fn drives_nominally(&self) -> bool {
        self.wheel_scale == [1.0, 1.0] && self.motor_lag.is_none() && self.latency == 0.0
    }
    /// Whether the robot senses as the nominal model does.
    pub fn senses_nominally(&self) -> bool {
        self.sensor_gain == 1.0 && self.sensor_offset == 0.0
    }
    fn overlay(&mut self, e: &RobotIndividual) {
        if let Some(v) = e.wheel_scale {
            self.wheel_scale = v;
        }
        if let Some(v) = e.motor_lag {
            self.motor_lag = Some(v);
        }
        if let Some(v) = e.latency {
            self.latency = v;
        }
        if let Some(v) = e.sensor_gain {
            self.sensor_gain = v;
        }
        if let Some(v) = e.sensor_offset {
            self.sensor_offset = v;
        }
    }
}

/// Checks every entry of `entries` for a scenario of `robots` robots; errors name the key as
/// `{prefix}[n].field` and the value.
pub fn validate_entries(entries: &[RobotIndividual], prefix: &str, robots: usize) -> Result<()> {
    let mut seen = vec![false; robots];
    for (n, e) in entries.iter().enumerate() {
        let key = |field: &str| format!("{prefix}[{n}].{field}");
        if e.index >= robots {
            return Err(SimError::invalid(
                key("index"),
                e.index,
                format!("the scenario has {robots} robots (indices 0..{robots})"),
            ));
        }
        if std::mem::replace(&mut seen[e.index], true) {
            return Err(SimError::invalid(
                key("index"),
                e.index,
                "another entry already gives this robot's values",
            ));
        }
        let range = |field: &str, v: f32, lo: f32, hi: f32, open_lo: bool| {
            let ok = v.is_finite() && (if open_lo { v > lo } else { v >= lo }) && v <= hi;
            if ok {
                Ok(())
            } else {
                let bracket = if open_lo { "(" } else { "[" };
                Err(SimError::invalid(
                    key(field),
                    v,
                    format!("must lie in {bracket}{lo}, {hi}]"),
                ))
            }
        };
        if let Some([l, r]) = e.wheel_scale {
            range("wheel_scale", l, 0.0, 10.0, true)?;
            range("wheel_scale", r, 0.0, 10.0, true)?;
        }
        if let Some(v) = e.motor_lag {
            range("motor_lag", v, 0.0, 1.0, false)?;
        }
        if let Some(v) = e.latency {
            range("latency", v, 0.0, MAX_COMMAND_LATENCY, false)?;
        }
        if let Some(v) = e.sensor_gain {
            range("sensor_gain", v, 0.0, 100.0, true)?;
        }
        if let Some(v) = e.sensor_offset {
            range("sensor_offset", v, -65535.0, 65535.0, false)?;
        }
    }
    Ok(())
}

/// Every robot's values for `scenario` (`robots` robots): the file's entries, then the inline ones
/// over them. `None` where the scenario has no `[individual]` section (every robot nominal).
pub fn resolve(scenario: &super::Scenario, robots: usize) -> Result<Option<Vec<Individual>>> {
    let spec = &scenario.spec.individual;
    if spec.is_default() {
        return Ok(None);
    }
    let mut out = vec![Individual::default(); robots];
    if let Some(file) = &spec.file {
        let loaded = IndividualFile::load(&scenario.base_dir.join(file)).map_err(|e| {
            SimError::invalid("individual.file", format!("{file:?}"), e.to_string())
        })?;
        out = loaded
            .resolve(robots)
            .map_err(|e| SimError::invalid("individual.file", format!("{file:?}"), inner(e)))?;
    }
    for e in &spec.robot {
        out[e.index].overlay(e);
    }
    Ok(Some(out))
}

/// A robot's colour counts through its own gain and offset, kept in the sensor's `0..=65535`.
pub fn apply_sensor_gain(counts: &mut [[u16; 3]; 4], gain: f32, offset: f32) {
    for c in counts.iter_mut().flatten() {
        *c = (*c as f32 * gain + offset).round().clamp(0.0, 65535.0) as u16;
    }
}

/// The inverse of [`apply_sensor_gain`]: counts read through `gain` and `offset` as the nominal
/// sensor would have read them, `(count - offset) / gain`, kept in `0..=65535`.
pub fn undo_sensor_gain(counts: &mut [[u16; 3]; 4], gain: f32, offset: f32) {
    for c in counts.iter_mut().flatten() {
        *c = ((*c as f32 - offset) / gain).round().clamp(0.0, 65535.0) as u16;
    }
}

/// An error about a key inside a file, without the scenario's prefix (the file's key names it).
pub(super) fn inner(e: SimError) -> String {
    match e {
        SimError::Invalid { key, value, reason } => format!("`{key}` = {value}: {reason}"),
        other => other.to_string(),
    }
}
