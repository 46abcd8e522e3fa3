//! What the bridge writes into each robot's runtime parameter block before it starts the policy.
use super::{
    OnboardManifest, P_INV_MAX_SPEED, P_MAX_SPEED, RUNTIME_LEN, SENSOR_BLOCK, sensor_offset,
};
use crate::colias::{CommandPacket, HostCommand, TELEMETRY_TO_SIM};
use colcos_sim::sensors::{ColourCalibration, invert3};

/// Robot `radio`'s parameters: the manifest's defaults; `max_wheel_speed` (m/s: the rig's limit, which
/// only the robot can enforce once the policy drives it); its four sensors' fits from `calibration`
/// when the file has the robot (the simulator's sensor order mapped onto the telemetry's).
pub fn robot_params(
    manifest: &OnboardManifest,
    max_wheel_speed: f32,
    calibration: Option<&ColourCalibration>,
    radio: u8,
) -> Vec<f32> {
    let mut p = manifest.runtime_defaults.clone();
    p.resize(RUNTIME_LEN, 0.0);
    if max_wheel_speed.is_finite() && max_wheel_speed > 0.0 {
        p[P_MAX_SPEED] = max_wheel_speed;
        p[P_INV_MAX_SPEED] = 1.0 / max_wheel_speed;
    }
    let Some((cal, robot)) = calibration.and_then(|c| Some((c, c.robot(radio)?))) else {
        return p;
    };
    for (w, &slot) in TELEMETRY_TO_SIM.iter().enumerate() {
        let fit = &robot.sensors[slot];
        let crosstalk = fit.crosstalk.map(|r| r.map(|v| v as f32));
        let scale = fit.gain as f32 * cal.integration_ms as f32;
        let (Some(inverse), true) = (invert3(&crosstalk), scale > 0.0 && fit.gamma > 0.0) else {
            // A sensor the calibration cannot invert keeps the export's model.
            continue;
        };
        let block = &mut p[sensor_offset(w)..sensor_offset(w) + SENSOR_BLOCK];
        block[..3].copy_from_slice(&fit.dark.map(|d| d as f32));
        block[3] = scale;
        block[4] = 1.0 / fit.gamma as f32;
        for (k, v) in inverse.iter().flatten().enumerate() {
            block[5 + k] = *v;
        }
    }
    p
}

/// `params` as `PWP` frames of five values each, for robot `radio`.
pub fn upload_packets(radio: u8, t_ms: u32, params: &[f32]) -> Vec<CommandPacket> {
    params
        .chunks(5)
        .enumerate()
        .map(|(k, chunk)| {
            let mut values = [0.0; 5];
            values[..chunk.len()].copy_from_slice(chunk);
            CommandPacket::new(
                radio,
                t_ms,
                HostCommand::WriteParamsAt {
                    offset: (5 * k) as u16,
                    count: chunk.len() as u8,
                    values,
                },
            )
        })
        .collect()
}
