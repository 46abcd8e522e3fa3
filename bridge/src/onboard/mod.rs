//! Policies on board: a policy exported to C by `colcos.onboard.export_c` runs on the robots
//! themselves. Its manifest (`<stem>.json`, named by the scenario's `[rig] onboard`) tells the bridge
//! the policy's hash and its runtime parameter block; the bridge writes each robot's parameters with
//! `PWP` (the largest wheel speed, its sensors' calibration, the bumper span), starts the policy with
//! `PRN` and from then on sends only stops. The digital twin compiles the same C and runs it on each
//! simulated robot's own readings ([`OnboardFleet`]), so the firmware's code is what the twin tests.
mod firmware;
mod fleet;
mod manifest;
mod upload;

pub use firmware::{OnboardFirmware, RawReadings};
pub use fleet::OnboardFleet;
pub use manifest::{ManifestEncoding, OnboardManifest};
pub use upload::robot_params;
pub(crate) use upload::upload_packets;

/// f32 values in the runtime parameter block (`<PREFIX>_N_RUNTIME`).
pub const RUNTIME_LEN: usize = 59;
/// Index of the largest wheel speed, m/s.
pub(crate) const P_MAX_SPEED: usize = 0;
/// Index of its reciprocal.
pub(crate) const P_INV_MAX_SPEED: usize = 1;
/// Index of the IR bumpers' span (counts, emitter on minus off, at contact).
pub(crate) const P_BUMPER_SPAN: usize = 2;
/// Values per colour sensor: dark R, G, B; gain x integration; 1 / gamma; inverse crosstalk (9).
pub(crate) const SENSOR_BLOCK: usize = 14;

/// First index of colour sensor `w`'s block (telemetry order: front, back, left, right).
pub(crate) const fn sensor_offset(w: usize) -> usize {
    3 + SENSOR_BLOCK * w
}

/// Whether index `i` holds a scale or a span (which must stay > 0), as the C's check.
pub(crate) fn positive_slot(i: usize) -> bool {
    i <= P_BUMPER_SPAN || matches!((i - 3) % SENSOR_BLOCK, 3 | 4)
}
