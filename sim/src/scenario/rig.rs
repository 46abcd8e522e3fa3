//! The `[rig]` section: how a scenario runs on the lab's hardware through the bridge (and on its
//! digital twin): which tracker marker and radio address each robot has, where its readings come
//! from, what its firmware understands, and the safety limits. A scenario without the section runs
//! on the rig with the defaults below.
use crate::error::{Result, SimError};
use crate::shield::ShieldParams;
use serde::{Deserialize, Serialize};

/// The radio address every robot listens to.
pub const BROADCAST_ID: u8 = 200;

/// Where a behaviour's colour and bumper readings come from on the rig.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SensorSource {
    /// Computed from the displayed screen at the tracked pose, by the simulator's sensor model.
    #[default]
    Virtual,
    /// The robots' own colour sensors and IR bumpers, from telemetry.
    Robot,
}

/// What the robots' firmware understands.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Firmware {
    /// The wheel-speed command `MWS` (two `f32`, m/s).
    #[default]
    Wheels,
    /// Only the original motion commands (`MFD`, `MBK`, `MML`, `MMR`, `MSP` with a speed): wheel
    /// speeds are mapped onto the nearest of them.
    Motion,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RigSpec {
    /// Tracker marker ID of each robot in scenario order (empty: 0, 1, 2, ...).
    pub tracker_ids: Vec<i32>,
    /// Radio address of each robot in scenario order (empty: 1, 2, 3, ...; 200 is the broadcast).
    pub radio_ids: Vec<u8>,
    pub sensors: SensorSource,
    pub firmware: Firmware,
    /// Latency compensation, s: each pose is predicted this far ahead (plus its age) from the robot's
    /// last command before pheromone is injected there. 0: none, as the paper's rig.
    pub latency: f32,
    /// Telemetry requests per robot per second (each frame takes ~8.7 ms of airtime at 115,200 baud).
    pub telemetry_hz: f32,
    /// Commands are re-sent at this rate even when unchanged, Hz; the firmware should stop a robot
    /// that has heard nothing for a few of these periods.
    pub keepalive_hz: f32,
    /// Every robot stops when the tracker has been silent this long, s.
    pub tracker_silence: f32,
    /// A robot stops when it has had no fresh pose this long, s.
    pub pose_age: f32,
    /// Every robot stops when the policy has not stepped this long, s.
    pub policy_stall: f32,
    /// The safety shield applied to every command (also in the simulator's environments).
    pub shield: ShieldParams,
    /// A screen <-> camera calibration file (`colcos calibrate screen`), relative to the scenario's
    /// directory: every tracker pose goes through it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub screen_calibration: Option<String>,
    /// A per-robot colour sensor calibration file (`colcos calibrate colour`), relative to the
    /// scenario's directory: the robots' raw counts go through its calibrated inverse.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub colour_calibration: Option<String>,
    /// An on-board policy (the `.json` `colcos.onboard.export_c` writes beside the C), relative to
    /// the scenario's directory: the robots run it themselves; the bridge uploads its runtime
    /// parameters, starts it and sends only stops; the digital twin runs its C.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub onboard: Option<String>,
    /// The robots' identified values (a file of `[[robot]]` entries, as `colcos rig identify`
    /// writes), relative to the scenario's directory: each robot's wheel commands are divided by its
    /// wheel scales and its own colour counts mapped back through its sensor gain and offset, so that
    /// the robots drive and sense as the scenario's nominal robot (motor lags and latencies stay).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub compensate: Option<String>,
}

impl Default for RigSpec {
    fn default() -> Self {
        RigSpec {
            tracker_ids: Vec::new(),
            radio_ids: Vec::new(),
            sensors: SensorSource::Virtual,
            firmware: Firmware::Wheels,
            latency: 0.0,
            telemetry_hz: 5.0,
            keepalive_hz: 10.0,
            tracker_silence: 0.1,
            pose_age: 0.3,
            policy_stall: 0.2,
            shield: ShieldParams::default(),
            screen_calibration: None,
            colour_calibration: None,
            onboard: None,
            compensate: None,
        }
    }
}

impl RigSpec {
    pub fn is_default(&self) -> bool {
        *self == RigSpec::default()
    }

    /// Tracker marker ID of robot `i`.
    pub fn tracker_id(&self, i: usize) -> i32 {
        self.tracker_ids.get(i).copied().unwrap_or(i as i32)
    }

    /// Radio address of robot `i` (`None`: the default addresses run out at 199).
    pub fn radio_id(&self, i: usize) -> Option<u8> {
        match self.radio_ids.get(i) {
            Some(id) => Some(*id),
            None if i + 1 < BROADCAST_ID as usize => Some((i + 1) as u8),
            None => None,
        }
    }

    /// Every robot's radio address, for a rig of `robots` robots: an error naming `rig.radio_ids` when
    /// the defaults run out (a radio reaches at most 199 robots).
    pub fn radio_addresses(&self, robots: usize) -> Result<Vec<u8>> {
        (0..robots)
            .map(|i| {
                self.radio_id(i).ok_or_else(|| {
                    SimError::invalid(
                        "rig.radio_ids",
                        "(default)",
                        format!("{robots} robots: the default addresses 1..=199 run out; a radio reaches at most 199 robots"),
                    )
                })
            })
            .collect()
    }

    /// Checks the section for a scenario of `robots` robots.
    pub fn validate(&self, robots: usize) -> Result<()> {
        let count = |key: &str, n: usize| {
            if n != 0 && n != robots {
                return Err(SimError::invalid(
                    format!("rig.{key}"),
                    format!("{n} entries"),
                    format!("one per robot: the scenario has {robots}"),
                ));
            }
            Ok(())
        };
        count("tracker_ids", self.tracker_ids.len())?;
        count("radio_ids", self.radio_ids.len())?;
        for (i, id) in self.radio_ids.iter().enumerate() {
            if *id == BROADCAST_ID || self.radio_ids[..i].contains(id) {
                return Err(SimError::invalid(
                    format!("rig.radio_ids[{i}]"),
                    id,
                    "must be unique and not the broadcast address 200",
                ));
            }
        }
        for (i, id) in self.tracker_ids.iter().enumerate() {
            if !(0..=999).contains(id) || self.tracker_ids[..i].contains(id) {
                return Err(SimError::invalid(
                    format!("rig.tracker_ids[{i}]"),
                    id,
                    "must be unique, 0..=999",
                ));
            }
        }
        let within = |key: &str, v: f32, lo: f32, hi: f32| {
            if v.is_finite() && (lo..=hi).contains(&v) {
                Ok(())
            } else {
                Err(SimError::invalid(
                    format!("rig.{key}"),
                    v,
                    format!("must be in [{lo}, {hi}]"),
                ))
            }
        };
        within("latency", self.latency, 0.0, 0.5)?;
        within("telemetry_hz", self.telemetry_hz, 0.0, 50.0)?;
        within("keepalive_hz", self.keepalive_hz, 1.0, 50.0)?;
        within("tracker_silence", self.tracker_silence, 0.02, 10.0)?;
        within("pose_age", self.pose_age, 0.02, 10.0)?;
        within("policy_stall", self.policy_stall, 0.02, 10.0)?;
        within(
            "shield.max_wheel_speed",
            self.shield.max_wheel_speed,
            0.0,
            2.0,
        )?;
        within("shield.margin", self.shield.margin, 0.0, 1.0)?;
        within("shield.horizon", self.shield.horizon, 0.0, 2.0)?;
        for (key, path) in [
            ("screen_calibration", &self.screen_calibration),
            ("colour_calibration", &self.colour_calibration),
            ("onboard", &self.onboard),
            ("compensate", &self.compensate),
        ] {
            if path.as_ref().is_some_and(|p| p.trim().is_empty()) {
                return Err(SimError::invalid(
                    format!("rig.{key}"),
                    "\"\"",
                    "must name a file",
                ));
            }
        }
        if self.onboard.is_some() && self.firmware == Firmware::Motion {
            return Err(SimError::invalid(
                "rig.firmware",
                "\"motion\"",
                "an on-board policy (rig.onboard) needs the firmware that runs it: \"wheels\"",
            ));
        }
        if let Some(file) = &self.compensate {
            let clash = if self.onboard.is_some() {
                Some(
                    "an on-board policy (rig.onboard) drives the wheels itself: the host cannot scale its commands",
                )
            } else if self.colour_calibration.is_some() {
                Some(
                    "rig.colour_calibration already maps the robots' counts onto the nominal sensor: name one of the two",
                )
            } else {
                None
            };
            if let Some(reason) = clash {
                return Err(SimError::invalid(
                    "rig.compensate",
                    format!("{file:?}"),
                    reason,
                ));
            }
        }
        Ok(())
    }
}
