//! What one robot senses, and what it commands.

use serde::{Deserialize, Serialize};

/// Index of the front-left bumper in [`Observation::bumpers`].
pub const BUMPER_FRONT_LEFT: usize = 0;
/// Index of the front bumper.
pub const BUMPER_FRONT: usize = 1;
/// Index of the front-right bumper.
pub const BUMPER_FRONT_RIGHT: usize = 2;

/// Target wheel surface speeds in m/s (positive drives forward). The drive model clamps them to the
/// robot's limits and applies the motor lag.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct WheelCommand {
    pub left: f32,
    pub right: f32,
}

impl WheelCommand {
    pub const STOP: WheelCommand = WheelCommand {
        left: 0.0,
        right: 0.0,
    };

    pub fn new(left: f32, right: f32) -> Self {
        WheelCommand { left, right }
    }
}

/// Everything a robot senses in one control step: what the real Colias can sense too.
///
/// Colour sensors are indexed `n = 0..3` for the robot-frame positions `Y-` (right), `X+` (front),
/// `Y+` (left), `X-` (back), as in the paper.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Observation {
    /// Simulation time of the reading, s.
    pub time: f32,
    /// Raw 16-bit counts per sensor and channel (r, g, b).
    pub counts: [[u16; 3]; 4],
    /// Calibrated screen intensity per sensor and channel, in `[0, 1]` (1 = full 8-bit level 255),
    /// recovered from the counts by the sensor's calibrated inverse. Channel `c` carries the pheromone
    /// drawn in that colour.
    pub intensity: [[f32; 3]; 4],
    /// IR bumper readings in `[0, 1]`: front-left, front, front-right; rises as an obstacle nears.
    pub bumpers: [f32; 3],
    /// The wheel command the robot sent in the previous step.
    pub last_command: WheelCommand,
}

impl Observation {
    /// Robot pheromone strength of channel `c`: the mean of its four sensors (paper, section II-D).
    pub fn strength(&self, c: usize) -> f32 {
        self.intensity.iter().map(|s| s[c]).sum::<f32>() / 4.0
    }

    /// Egocentric direction of the positive gradient of channel `c`, eq. (6), in radians counter-clockwise
    /// from the robot's forward axis: `atan2(Phi_2 - Phi_0, Phi_1 - Phi_3)`.
    pub fn gradient_direction(&self, c: usize) -> f32 {
        let s = &self.intensity;
        (s[2][c] - s[0][c]).atan2(s[1][c] - s[3][c])
    }

    /// Strongest bumper reading.
    pub fn max_bumper(&self) -> f32 {
        self.bumpers.iter().copied().fold(0.0, f32::max)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn obs_with(channel: usize, per_sensor: [f32; 4]) -> Observation {
        let mut o = Observation::default();
        for (n, v) in per_sensor.into_iter().enumerate() {
            o.intensity[n][channel] = v;
        }
        o
    }

    #[test]
    fn gradient_points_to_the_stronger_side() {
        // Stronger at the front sensor (X+): direction 0.
        assert!(
            obs_with(1, [0.2, 0.8, 0.2, 0.0])
                .gradient_direction(1)
                .abs()
                < 1e-6
        );
        // Stronger at the left sensor (Y+): +pi/2.
        let left = obs_with(1, [0.0, 0.2, 0.8, 0.2]).gradient_direction(1);
        assert!((left - std::f32::consts::FRAC_PI_2).abs() < 1e-6);
        // Stronger at the right sensor (Y-): -pi/2.
        let right = obs_with(1, [0.8, 0.2, 0.0, 0.2]).gradient_direction(1);
        assert!((right + std::f32::consts::FRAC_PI_2).abs() < 1e-6);
    }

    #[test]
    fn strength_is_the_mean() {
        assert!((obs_with(0, [0.1, 0.2, 0.3, 0.4]).strength(0) - 0.25).abs() < 1e-6);
    }
}
