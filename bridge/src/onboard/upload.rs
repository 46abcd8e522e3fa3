//! What the bridge writes into each robot's runtime parameter block before it starts the policy.
use super::{
    OnboardManifest, P_INV_MAX_SPEED, P_MAX_SPEED, RUNTIME_LEN, SENSOR_BLOCK, sensor_offset,
};
use crate::protocol::colias::{CommandPacket, HostCommand, TELEMETRY_TO_SIM};
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
pub(crate) fn upload_packets(radio: u8, t_ms: u32, params: &[f32]) -> Vec<CommandPacket> {
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::onboard::{ManifestEncoding, P_BUMPER_SPAN};
    use colcos_sim::sensors::{RobotColour, SensorFit};

    fn manifest() -> OnboardManifest {
        OnboardManifest {
            format: super::super::manifest::FORMAT.into(),
            prefix: "p".into(),
            hash: 1,
            source: "p.c".into(),
            header: "p.h".into(),
            layer_sizes: vec![17, 2],
            activations: vec!["identity".into()],
            runtime_defaults: (0..RUNTIME_LEN).map(|i| 1.0 + i as f32).collect(),
            encoding: ManifestEncoding {
                gamma: 2.2,
                crosstalk: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
                gain: 1500.0,
                integration_ms: 24.0,
                dark_counts: 30.0,
                max_wheel_speed: 0.35,
                bumper_span: 3000.0,
                dt: 0.02,
            },
            dir: Default::default(),
        }
    }

    #[test]
    fn a_robots_sensors_land_in_telemetry_order() {
        // Simulator slot s has gain 1000 + 100 s and dark 10 + s.
        let fit = |s: usize| {
            SensorFit::from_parts(
                2.0,
                1000.0 + 100.0 * s as f64,
                [[1.0, 0.1, 0.0], [0.0, 1.0, 0.2], [0.0, 0.0, 1.0]],
                [10.0 + s as f64; 3],
                20.0,
            )
        };
        let cal = ColourCalibration::new(
            "2026-01-01T00:00:00Z".into(),
            20.0,
            vec![RobotColour {
                radio_id: 7,
                sensors: std::array::from_fn(fit),
            }],
            0.0,
        );
        let m = manifest();
        let p = robot_params(&m, 0.25, Some(&cal), 7);
        assert_eq!((p[P_MAX_SPEED], p[P_INV_MAX_SPEED]), (0.25, 4.0));
        assert_eq!(p[P_BUMPER_SPAN], m.runtime_defaults[P_BUMPER_SPAN]);
        for (w, &slot) in TELEMETRY_TO_SIM.iter().enumerate() {
            let b = &p[sensor_offset(w)..sensor_offset(w) + SENSOR_BLOCK];
            assert_eq!(b[0], 10.0 + slot as f32, "sensor {w}");
            assert_eq!(b[3], (1000.0 + 100.0 * slot as f32) * 20.0);
            assert_eq!(b[4], 0.5);
            // The inverse crosstalk: row 0 of [[1, .1, 0], [0, 1, .2], [0, 0, 1]]^-1 is [1, -.1, .02].
            assert!(
                (b[5] - 1.0).abs() < 1e-6
                    && (b[6] + 0.1).abs() < 1e-6
                    && (b[7] - 0.02).abs() < 1e-6
            );
        }
        // A robot the file does not have keeps the export's sensors; a bad limit keeps its speed.
        let other = robot_params(&m, f32::NAN, Some(&cal), 8);
        assert_eq!(other, m.runtime_defaults);
    }

    #[test]
    fn uploads_are_frames_of_five_at_their_offsets() {
        let params: Vec<f32> = (0..RUNTIME_LEN).map(|i| i as f32).collect();
        let frames = upload_packets(3, 42, &params);
        assert_eq!(frames.len(), 12);
        for (k, f) in frames.iter().enumerate() {
            let HostCommand::WriteParamsAt {
                offset,
                count,
                values,
            } = f.command
            else {
                panic!("{f:?}");
            };
            assert_eq!((f.id, f.t_ms, offset as usize), (3, 42, 5 * k));
            let n = if k == 11 { 4 } else { 5 };
            assert_eq!(count as usize, n);
            assert_eq!(&values[..n], &params[5 * k..5 * k + n]);
        }
    }
}
