//! System identification from Python (`colcos.rig.identify`): a rig log and its scenario in, each
//! robot's fitted values (or why a value could not be fitted) out as JSON text, and the file of
//! per-robot values written where asked, as `colcos rig identify` does. The GIL is released while
//! the log is read and fitted.
use crate::args::guard;
use crate::errors::Kind;
use colcos_bridge::identify::{self, FitOptions, Identified, Param};
use colcos_sim::scenario::Scenario;
use pyo3::exceptions::PyOSError;
use pyo3::prelude::*;
use serde_json::{Value, json};
use std::path::PathBuf;

/// Identifies every robot of the scenario file `scenario` from the rig log `log`; writes the file
/// of per-robot values to `out` when given. Returns the fit as JSON text.
#[pyfunction]
#[pyo3(signature = (log, scenario, out=None, pose_delay=None))]
fn rig_identify(
    py: Python<'_>,
    log: PathBuf,
    scenario: PathBuf,
    out: Option<PathBuf>,
    pose_delay: Option<f64>,
) -> PyResult<String> {
    guard(|| {
        if let Some(d) = pose_delay
            && !(d.is_finite() && (0.0..=1.0).contains(&d))
        {
            return Err(Kind::Colcos.err(format!("pose_delay = {d}: must be in [0, 1] s")));
        }
        let sc = py
            .detach(|| Scenario::from_file(&scenario))
            .map_err(|e| Kind::Scenario.err(e.to_string()))?;
        let bytes = std::fs::read(&log)
            .map_err(|e| PyOSError::new_err(format!("reading {}: {e}", log.display())))?;
        let opts = FitOptions {
            pose_delay,
            ..FitOptions::default()
        };
        let found = py
            .detach(|| identify::identify(&bytes, &sc, &opts))
            .map_err(|e| Kind::Colcos.err(format!("identifying from {}: {e}", log.display())))?;
        let file = identify::overlay::overlay(&found, &log.display().to_string(), &sc.spec.name);
        let text = file.to_toml();
        if let Some(out) = &out {
            std::fs::write(out, &text)
                .map_err(|e| PyOSError::new_err(format!("writing {}: {e}", out.display())))?;
        }
        Ok(to_json(&found, &text).to_string())
    })
}

/// The fit as JSON: every parameter as `{"value", "sd"}` or `{"why"}`.
fn to_json(found: &Identified, overlay: &str) -> Value {
    fn one(p: &Param<f64>) -> Value {
        match p {
            Ok((v, sd)) => json!({"value": v, "sd": sd}),
            Err(why) => json!({"why": why}),
        }
    }
    let robots: Vec<Value> = (found.robots.iter())
        .map(|f| {
            json!({
                "index": f.index,
                "wheel_scale": match &f.wheel_scale {
                    Ok((v, sd)) => json!({"value": v, "sd": sd}),
                    Err(why) => json!({"why": why}),
                },
                "motor_lag": one(&f.motor_lag),
                "latency": one(&f.latency),
                "sensor_gain": one(&f.sensor.gain),
                "sensor_offset": one(&f.sensor.offset),
                "windows": f.windows,
                "outliers": f.outliers,
                "readings": f.sensor.readings,
                "readings_used": f.sensor.used,
            })
        })
        .collect();
    json!({
        "robots": robots,
        "duration": found.duration,
        "pose_delay": found.pose_delay,
        "tracker_latency": found.tracker_latency,
        "telemetry_round_trip": found.round_trip,
        "overlay": overlay,
    })
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(rig_identify, m)?)?;
    Ok(())
}
