//! The excitation `colcos rig excite` drives: per robot, a sequence of held wheel commands of random
//! length (steps that reveal the latency and the motor lag), mostly driving forward on two different
//! wheel speeds (revealing each wheel's scale through the turning and the driving), sometimes
//! turning on the spot or standing still. Bounded: every wheel at most `max_speed`. Stateless in
//! time: the command at `t` follows from the seed, the robot and `t` alone, so a replay or a test
//! gets the same sequence.
use colcos_sim::behaviour::WheelCommand;

#[derive(Clone, Copy, Debug)]
pub struct Excitation {
    pub seed: u64,
    /// Largest wheel speed commanded, m/s.
    pub max_speed: f32,
    /// Shortest and longest time a command is held, s.
    pub hold: [f32; 2],
}

impl Excitation {
    pub fn new(seed: u64, max_speed: f32) -> Self {
        Excitation {
            seed,
            max_speed,
            hold: [0.25, 0.8],
        }
    }

    /// Robot `robot`'s command at `t` s from the excitation's start.
    pub fn command(&self, robot: usize, t: f64) -> WheelCommand {
        // Before the start, and for a NaN time, nothing moves.
        if t.is_nan() || t < 0.0 {
            return WheelCommand::STOP;
        }
        // Walk the segments from the start: each is its own hash, so no state is kept.
        let mut start = 0.0f64;
        let mut k = 0u64;
        loop {
            let h = |j: u64| unit(mix(self.seed, robot as u64, k * 8 + j));
            let len = self.hold[0] as f64 + (self.hold[1] - self.hold[0]) as f64 * h(0);
            if t < start + len {
                return self.segment(h(1), h(2), h(3));
            }
            start += len;
            k += 1;
        }
    }

    fn segment(&self, mode: f64, a: f64, b: f64) -> WheelCommand {
        let v = self.max_speed;
        let (left, right) = if mode < 0.65 {
            // Driving on two wheel speeds between 30 % and 100 % of the limit: curves both ways.
            ((0.3 + 0.7 * a) as f32 * v, (0.3 + 0.7 * b) as f32 * v)
        } else if mode < 0.85 {
            let s = (0.3 + 0.5 * a) as f32 * v;
            if b < 0.5 { (-s, s) } else { (s, -s) }
        } else {
            (0.0, 0.0)
        };
        WheelCommand { left, right }
    }
}

/// splitmix64 of the three numbers.
fn mix(seed: u64, robot: u64, k: u64) -> u64 {
    let mut z = seed
        .wrapping_mul(0x9E37_79B9_7F4A_7C15)
        .wrapping_add(robot.wrapping_mul(0xBF58_476D_1CE4_E5B9))
        .wrapping_add(k.wrapping_mul(0x94D0_49BB_1331_11EB))
        .wrapping_add(0x632B_E59B_D9B4_E019);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// A hash as a number in [0, 1).
fn unit(h: u64) -> f64 {
    (h >> 11) as f64 / (1u64 << 53) as f64
}
