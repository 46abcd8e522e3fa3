//! Identification's result as a file of per-robot values (`[[robot]]` entries with their `*_sd`
//! uncertainties), the format `[individual] file` and `colcos twin --truth` read. A parameter that
//! could not be identified is left out of its robot's entry (the robot keeps the nominal value) and
//! its reason goes into the `[identified]` notes. The sensor's gain and offset go together: one
//! without the other would misplace every count.
use super::Identified;
use colcos_sim::scenario::{IndividualFile, RobotIndividual};

/// The file for `found`, noting the `log` and `scenario` it came from.
pub fn overlay(found: &Identified, log: &str, scenario: &str) -> IndividualFile {
    let mut notes = toml::Table::new();
    notes.insert("log".into(), log.into());
    notes.insert("scenario".into(), scenario.into());
    notes.insert(
        "duration_s".into(),
        toml::Value::Float(round(found.duration, 3)),
    );
    notes.insert(
        "pose_delay".into(),
        toml::Value::Float(round(found.pose_delay, 4)),
    );
    if let Some(t) = found.round_trip {
        notes.insert(
            "telemetry_round_trip".into(),
            toml::Value::Float(round(t, 4)),
        );
    }
    if let Some(t) = found.tracker_latency {
        notes.insert("tracker_latency".into(), toml::Value::Float(round(t, 4)));
    }
    if let Some((p, h)) = found.tracker_noise() {
        // Upper bounds: what the drive model misses counts as noise too.
        notes.insert(
            "position_noise_at_most".into(),
            toml::Value::Float(round(p, 5)),
        );
        notes.insert(
            "heading_noise_at_most".into(),
            toml::Value::Float(round(h, 4)),
        );
    }
    let mut unidentified = toml::Table::new();
    let robot = found
        .robots
        .iter()
        .map(|f| {
            let mut e = RobotIndividual {
                index: f.index,
                ..Default::default()
            };
            let mut why = Vec::new();
            match &f.wheel_scale {
                Ok((v, sd)) => {
                    e.wheel_scale = Some(v.map(|x| round(x, 4) as f32));
                    e.wheel_scale_sd = Some(sd.map(|x| round(x, 4) as f32));
                }
                Err(r) => why.push(format!("wheel_scale: {r}")),
            }
            match &f.motor_lag {
                Ok((v, sd)) => {
                    e.motor_lag = Some(round(*v, 4) as f32);
                    e.motor_lag_sd = Some(round(*sd, 4) as f32);
                }
                Err(r) => why.push(format!("motor_lag: {r}")),
            }
            match &f.latency {
                Ok((v, sd)) => {
                    e.latency = Some(round(*v, 4) as f32);
                    e.latency_sd = Some(round(*sd, 4) as f32);
                }
                Err(r) => why.push(format!("latency: {r}")),
            }
            match (&f.sensor.gain, &f.sensor.offset) {
                (Ok((g, g_sd)), Ok((o, o_sd))) => {
                    e.sensor_gain = Some(round(*g, 4) as f32);
                    e.sensor_gain_sd = Some(round(*g_sd, 4) as f32);
                    e.sensor_offset = Some(round(*o, 1) as f32);
                    e.sensor_offset_sd = Some(round(*o_sd, 1) as f32);
                }
                (Err(r), _) | (_, Err(r)) => why.push(format!("sensor_gain: {r}")),
            }
            if !why.is_empty() {
                unidentified.insert(
                    format!("robot{}", f.index),
                    toml::Value::Array(why.into_iter().map(toml::Value::from).collect()),
                );
            }
            e
        })
        .collect();
    if !unidentified.is_empty() {
        notes.insert("unidentifiable".into(), toml::Value::Table(unidentified));
    }
    IndividualFile {
        identified: Some(notes),
        robot,
    }
}

fn round(x: f64, digits: i32) -> f64 {
    let p = 10f64.powi(digits);
    (x * p).round() / p
}
