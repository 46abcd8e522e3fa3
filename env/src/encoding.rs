//! What an agent sees and does, as numbers: its own sensor reading as a normalised vector, and its
//! action as a wheel command.
use colcos_sim::behaviour::{Observation, WheelCommand};

/// Length of the observation vector: 4 sensors x 3 channels, 3 bumpers, 2 wheel commands.
pub const OBS_DIM: usize = 17;

/// Names of the observation vector's entries, in order.
pub const OBS_NAMES: [&str; OBS_DIM] = [
    "right_r",
    "right_g",
    "right_b",
    "front_r",
    "front_g",
    "front_b",
    "left_r",
    "left_g",
    "left_b",
    "back_r",
    "back_g",
    "back_b",
    "bumper_front_left",
    "bumper_front",
    "bumper_front_right",
    "last_left",
    "last_right",
];

/// Writes an observation: intensities in `[0, 1]` (sensors n = 0..3: right, front, left, back), bumpers
/// in `[0, 1]`, and the last wheel command as a fraction of `max_speed` in `[-1, 1]`.
#[inline]
pub fn encode(obs: &Observation, max_speed: f32, out: &mut [f32]) {
    debug_assert_eq!(out.len(), OBS_DIM);
    for n in 0..4 {
        out[3 * n..3 * n + 3].copy_from_slice(&obs.intensity[n]);
    }
    out[12..15].copy_from_slice(&obs.bumpers);
    let inv = if max_speed > 0.0 {
        1.0 / max_speed
    } else {
        0.0
    };
    out[15] = (obs.last_command.left * inv).clamp(-1.0, 1.0);
    out[16] = (obs.last_command.right * inv).clamp(-1.0, 1.0);
}

/// The discrete actions as (left, right) fractions of the largest wheel speed.
pub const DISCRETE_ACTIONS: [(f32, f32); 6] = [
    (0.0, 0.0),    // 0 stop
    (0.5, 0.5),    // 1 forward
    (0.25, 0.5),   // 2 forward, curving left
    (0.5, 0.25),   // 3 forward, curving right
    (-0.25, 0.25), // 4 pivot left
    (0.25, -0.25), // 5 pivot right
];

/// A continuous action (fractions of `max_speed`, clamped to `[-1, 1]`) as a wheel command, m/s.
#[inline]
pub fn continuous_command(left: f32, right: f32, max_speed: f32) -> WheelCommand {
    WheelCommand::new(
        left.clamp(-1.0, 1.0) * max_speed,
        right.clamp(-1.0, 1.0) * max_speed,
    )
}

/// A discrete action as a wheel command, m/s (`None` if out of range).
#[inline]
pub fn discrete_command(action: i64, max_speed: f32) -> Option<WheelCommand> {
    let (l, r) = *DISCRETE_ACTIONS.get(usize::try_from(action).ok()?)?;
    Some(WheelCommand::new(l * max_speed, r * max_speed))
}

/// A wheel command as the continuous action that produces it.
#[inline]
pub fn command_to_action(cmd: WheelCommand, max_speed: f32) -> [f32; 2] {
    let inv = if max_speed > 0.0 {
        1.0 / max_speed
    } else {
        0.0
    };
    [
        (cmd.left * inv).clamp(-1.0, 1.0),
        (cmd.right * inv).clamp(-1.0, 1.0),
    ]
}
