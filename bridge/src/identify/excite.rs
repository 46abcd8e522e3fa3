//! The excitation `colcos rig excite` drives: per robot, a sequence of held wheel commands of random
//! length (steps that reveal the latency and the motor lag), mostly driving forward on two different
//! wheel speeds (revealing each wheel's scale through the turning and the driving), sometimes
//! turning on the spot or standing still. Bounded: every wheel at most `max_speed`. Stateless in
//! time: the command at `t` follows from the seed, the robot and `t` alone, so a replay or a test
//! gets the same sequence. [`check_room`] refuses an excitation the arena and its shield cannot hold.
use colcos_sim::behaviour::WheelCommand;
use colcos_sim::scenario::Scenario;

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

/// Why an excitation with wheels up to `max_speed` m/s would leave `scenario`'s arena, or `Ok`:
/// every command goes through the shield, which stops a robot whose command would cross its virtual
/// walls within its look-ahead; the robot must then stop before its body reaches the arena's edge,
/// and there must be room between the walls to drive at all.
pub fn check_room(scenario: &Scenario, max_speed: f64) -> Result<(), String> {
    let shield = &scenario.spec.rig.shield;
    let robot = &scenario.spec.robot;
    let (margin, radius) = (shield.margin as f64, robot.radius as f64);
    if !(max_speed.is_finite() && max_speed > 0.0) {
        return Err(format!(
            "the excitation's wheel speed {max_speed} m/s: must be above 0"
        ));
    }
    if margin < radius {
        return Err(format!(
            "[rig] shield.margin = {} m is less than the robot's radius {} m: the excitation would \
             drive bodies past the arena's edge; widen the margin",
            shield.margin, robot.radius
        ));
    }
    // Between the walls: a robot's width and its turning circle on the spot, twice.
    let arena = scenario.arena_size();
    let room = [arena.x as f64 - 2.0 * margin, arena.y as f64 - 2.0 * margin];
    let need = 8.0 * radius;
    if room[0] < need || room[1] < need {
        return Err(format!(
            "the arena inside the shield's walls is {:.3} x {:.3} m ({} x {} m less \
             shield.margin = {} m on each side): the excitation needs at least {need:.3} m each \
             way to drive and turn",
            room[0].max(0.0),
            room[1].max(0.0),
            arena.x,
            arena.y,
            shield.margin
        ));
    }
    // Stopping from `max_speed`: the motor's first-order lag covers `speed x lag`, and the stop
    // goes out a tick or two late.
    let (lag, dt) = (robot.motor_lag.max(0.0) as f64, scenario.spec.dt as f64);
    let stopping = max_speed * (lag + 2.0 * dt);
    let room_to_stop = max_speed * shield.horizon.max(0.0) as f64 + (margin - radius);
    if stopping > room_to_stop {
        return Err(format!(
            "at {max_speed:.3} m/s a robot covers {stopping:.4} m while it stops (motor lag \
             {} s and two ticks of {} s), more than the shield's look-ahead ({} s: {:.4} m) \
             and the margin beyond its body ({:.4} m) leave: the excitation would carry robots \
             past the arena's edge; lower --speed or raise [rig] shield.horizon or shield.margin",
            robot.motor_lag,
            scenario.spec.dt,
            shield.horizon,
            max_speed * shield.horizon.max(0.0) as f64,
            margin - radius
        ));
    }
    Ok(())
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
