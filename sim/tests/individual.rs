//! `[individual]`: robots that differ. Each robot's own wheel scales, motor lag, command latency and
//! sensor gain against analytic solutions (the circle of a lopsided robot, the first-order step
//! response, a response delayed by whole steps), bad values refused by key and value, and
//! `[randomize]` drawing around each robot's own values.
use colcos_sim::behaviour::WheelCommand;
use colcos_sim::robot::Actuation;
use colcos_sim::scenario::{RobotGroupSpec, Scenario, ScenarioBuilder};
use colcos_sim::world::World;

/// One robot at the centre of a 1.2 m arena, heading +x (and a second near a corner), without sensor
/// noise or tracker latency: the scenario file with `extra` appended (e.g. `[individual]`).
fn scenario(extra: &str) -> Scenario {
    let base = ScenarioBuilder::new()
        .duration(20.0)
        .screen([240, 240], [1.2, 1.2])
        .with(|s| {
            s.sensor.noise = 0.0;
            s.tracker.latency = 0.0;
        })
        .robots(RobotGroupSpec::new(2, "wander").at_poses(vec![[0.6, 0.6, 0.0], [0.1, 0.1, 90.0]]))
        .build()
        .unwrap();
    Scenario::from_toml_str(&format!("{}\n{extra}\n", base.to_toml()), ".").unwrap()
}

fn left_speeds(world: &mut World, cmd: WheelCommand, steps: usize) -> Vec<f32> {
    (0..steps)
        .map(|_| {
            world.step_with_commands(&[cmd, WheelCommand::STOP]);
            world.robots()[0].drive.left
        })
        .collect()
}

/// Centre and radius of the circle through `points` (Kasa's algebraic least-squares fit, in f64).
fn fit_circle(points: &[[f64; 2]]) -> ([f64; 2], f64) {
    // x^2 + y^2 = 2 a x + 2 b y + c: linear in (a, b, c); normal equations by hand (3 x 3).
    let mut m = [[0.0f64; 3]; 3];
    let mut v = [0.0f64; 3];
    for &[x, y] in points {
        let row = [2.0 * x, 2.0 * y, 1.0];
        let rhs = x * x + y * y;
        for i in 0..3 {
            for j in 0..3 {
                m[i][j] += row[i] * row[j];
            }
            v[i] += row[i] * rhs;
        }
    }
    let det = |m: &[[f64; 3]; 3]| {
        m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
    };
    let d = det(&m);
    let solve = |k: usize| {
        let mut mk = m;
        (0..3).for_each(|i| mk[i][k] = v[i]);
        det(&mk) / d
    };
    let (a, b, c) = (solve(0), solve(1), solve(2));
    ([a, b], (c + a * a + b * b).sqrt())
}

#[test]
fn wheel_scales_of_1_and_0_9_drive_the_predicted_circle() {
    let sc = scenario("[[individual.robot]]\nindex = 0\nwheel_scale = [1.0, 0.9]");
    let mut world = World::new(&sc).unwrap();
    let b = sc.spec.robot.wheel_base as f64;
    // Both wheels commanded 0.1 m/s: left 0.1, right 0.09 once the lag settles, so forward 0.095 m/s
    // and yaw rate -0.01 / b: radius = 0.095 b / 0.01 = 9.5 b.
    let predicted = 9.5 * b;
    let cmd = WheelCommand {
        left: 0.1,
        right: 0.1,
    };
    let mut points = Vec::new();
    for k in 0..1000 {
        world.step_with_commands(&[cmd, WheelCommand::STOP]);
        // After 1 s (20 time constants) the transient is gone.
        if k >= 50 {
            let p = world.poses()[0].pos;
            points.push([p.x as f64, p.y as f64]);
        }
    }
    let (_, radius) = fit_circle(&points);
    let err = (radius - predicted).abs() / predicted;
    assert!(
        err < 0.01,
        "radius {radius:.4} m, predicted {predicted:.4} m ({:.2} %)",
        100.0 * err
    );
    // Turning right (clockwise): the right wheel is the slow one.
    let d = &world.robots()[0].drive;
    assert!((d.right / d.left - 0.9).abs() < 1e-5, "{d:?}");
}

#[test]
fn motor_lag_gives_the_first_order_step_response() {
    // tau = 0.1 s = 5 steps of 0.02 s: 1 - e^-1 = 63.2 % at tau, 86.5 % at 2 tau.
    let sc = scenario("[[individual.robot]]\nindex = 0\nmotor_lag = 0.1");
    let mut world = World::new(&sc).unwrap();
    let cmd = WheelCommand {
        left: 0.2,
        right: 0.2,
    };
    let v = left_speeds(&mut world, cmd, 10);
    for (k, got) in v.iter().enumerate() {
        let t = 0.02 * (k + 1) as f64;
        let want = 0.2 * (1.0 - (-t / 0.1).exp());
        assert!(
            (*got as f64 - want).abs() < 1e-6,
            "step {k}: {got} vs {want}"
        );
    }
    assert!((v[4] / 0.2 - 0.632).abs() < 1e-3, "at tau: {}", v[4] / 0.2);
    // The other robot keeps the nominal 0.05 s.
    assert_eq!(world.actuation(1), None);
}

#[test]
fn latency_delays_the_response_by_whole_steps() {
    let dt = 0.02;
    // round(latency / dt), half a step rounding up (away from zero).
    assert_eq!(Actuation::delay_steps(0.06, dt), 3);
    assert_eq!(Actuation::delay_steps(0.069, dt), 3);
    assert_eq!(Actuation::delay_steps(0.071, dt), 4);
    assert_eq!(Actuation::delay_steps(0.009, dt), 0);
    assert_eq!(Actuation::delay_steps(0.011, dt), 1);
    let cmd = WheelCommand {
        left: 0.2,
        right: 0.1,
    };
    let nominal = left_speeds(&mut World::new(&scenario("")).unwrap(), cmd, 40);
    let late = scenario("[[individual.robot]]\nindex = 0\nlatency = 0.06");
    let mut world = World::new(&late).unwrap();
    assert_eq!(world.actuation(0).map(Actuation::delay), Some(3));
    let delayed = left_speeds(&mut world, cmd, 40);
    assert!(
        delayed[..3].iter().all(|v| *v == 0.0),
        "{:?}",
        &delayed[..4]
    );
    // Bit for bit the nominal response, three steps later.
    assert_eq!(&delayed[3..], &nominal[..37]);
}

#[test]
fn an_entry_with_the_nominal_values_drives_bit_for_bit_as_none() {
    // motor_lag given explicitly at its nominal value builds an actuation of its own: its arithmetic
    // must be the nominal model's.
    let own = scenario("[[individual.robot]]\nindex = 0\nmotor_lag = 0.05\nlatency = 0.0");
    let mut a = World::new(&scenario("")).unwrap();
    let mut b = World::new(&own).unwrap();
    assert!(b.actuation(0).is_some());
    for k in 0..200 {
        let cmd = WheelCommand {
            left: 0.3 * (k as f32 * 0.05).sin(),
            right: 0.2,
        };
        a.step_with_commands(&[cmd, cmd]);
        b.step_with_commands(&[cmd, cmd]);
        assert_eq!(a.poses(), b.poses(), "step {k}");
    }
}

#[test]
fn sensor_gain_and_offset_act_on_the_counts() {
    let mut plain = World::new(&scenario("")).unwrap();
    let own = scenario("[[individual.robot]]\nindex = 0\nsensor_gain = 0.5\nsensor_offset = 100.0");
    let mut world = World::new(&own).unwrap();
    plain.step_with_commands(&[WheelCommand::STOP; 2]);
    world.step_with_commands(&[WheelCommand::STOP; 2]);
    let (a, b) = (plain.observations()[0], world.observations()[0]);
    for k in 0..4 {
        for c in 0..3 {
            let want = (a.counts[k][c] as f32 * 0.5 + 100.0).round() as u16;
            assert_eq!(b.counts[k][c], want, "sensor {k} channel {c}");
        }
    }
    assert_ne!(a.intensity, b.intensity);
    // Robot 1 has no entry: it reads as before.
    assert_eq!(plain.observations()[1], world.observations()[1]);
}

#[test]
fn bad_values_are_refused_with_key_and_value() {
    let cases = [
        (
            "index = 2\nwheel_scale = [1.0, 1.0]",
            "individual.robot[0].index",
            "2",
        ),
        (
            "index = 0\nwheel_scale = [1.0, -0.5]",
            "individual.robot[0].wheel_scale",
            "-0.5",
        ),
        (
            "index = 0\nmotor_lag = 3.0",
            "individual.robot[0].motor_lag",
            "3",
        ),
        (
            "index = 0\nlatency = -0.01",
            "individual.robot[0].latency",
            "-0.01",
        ),
        (
            "index = 0\nsensor_gain = 0.0",
            "individual.robot[0].sensor_gain",
            "0",
        ),
    ];
    for (entry, key, value) in cases {
        let text = format!(
            "duration = 1.0\n[[robots]]\ncount = 2\nbehaviour = \"wander\"\n[[individual.robot]]\n{entry}"
        );
        let err = Scenario::from_toml_str(&text, ".").unwrap_err().to_string();
        assert!(err.contains(key) && err.contains(value), "{entry}: {err}");
    }
    let text = "duration = 1.0\n[[robots]]\ncount = 1\nbehaviour = \"wander\"\n[[individual.robot]]\nindex = 0\nwheel = 1.0";
    let err = Scenario::from_toml_str(text, ".").unwrap_err().to_string();
    assert!(err.contains("wheel"), "{err}");
}

#[test]
fn a_file_of_entries_is_read_and_checked() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("robots.toml"),
        "[[robot]]\nindex = 1\nwheel_scale = [0.9, 1.1]\nlatency = 0.04\nwheel_scale_sd = [0.01, 0.01]\n",
    )
    .unwrap();
    let text = "duration = 1.0\n[[robots]]\ncount = 2\nbehaviour = \"wander\"\n[individual]\nfile = \"robots.toml\"\n[[individual.robot]]\nindex = 1\nlatency = 0.02";
    let sc = Scenario::from_toml_str(text, dir.path()).unwrap();
    let world = World::new(&sc).unwrap();
    let own = world.actuation(1).unwrap();
    assert_eq!(own.wheel_scale, [0.9, 1.1]);
    // The inline latency over the file's.
    assert_eq!(own.delay(), 1);
    assert!(world.actuation(0).is_none());

    // A bad file is refused when the world is built, naming the file's key.
    for (file, needles) in [
        (
            "[[robot]]\nindex = 1\nmotor_lag = -1.0\n",
            &["robots.toml", "robot[0].motor_lag", "-1"][..],
        ),
        (
            "[[robot]]\nindex = 1\nwheel_scale = [1.0, 0.9, 0.8]\n",
            &["robot[0].wheel_scale", "got 3"],
        ),
    ] {
        std::fs::write(dir.path().join("robots.toml"), file).unwrap();
        let err = World::new(&sc).err().unwrap().to_string();
        for n in needles {
            assert!(err.contains(n), "{file}: {err:?} does not mention {n:?}");
        }
    }
    let missing = text.replace("robots.toml", "absent.toml");
    let sc = Scenario::from_toml_str(&missing, dir.path()).unwrap();
    let err = World::new(&sc).err().unwrap().to_string();
    assert!(
        err.contains("individual.file") && err.contains("absent.toml"),
        "{err}"
    );
}

#[test]
fn randomize_draws_around_each_robots_own_values() {
    let sc = scenario(
        "[[individual.robot]]\nindex = 0\nwheel_scale = [1.0, 0.8]\nlatency = 0.1\n\
         [randomize]\nwheel_scale = [0.95, 1.05]\ncommand_latency = [0.0, 0.04]\nmotor_lag_factor = [0.5, 2.0]",
    );
    let mut right = Vec::new();
    for w in 0..16 {
        let world = World::with_index(&sc, w).unwrap();
        let a = world.actuation(0).unwrap();
        assert!((0.95..=1.05).contains(&a.wheel_scale[0]), "{a:?}");
        assert!((0.76..=0.84).contains(&a.wheel_scale[1]), "{a:?}");
        assert!((5..=7).contains(&a.delay()), "{a:?}");
        assert!((0.025..=0.1).contains(&a.motor_lag), "{a:?}");
        // Robot 1 has no entry: drawn around the nominal values.
        let b = world.actuation(1).unwrap();
        assert!((0.95..=1.05).contains(&b.wheel_scale[1]), "{b:?}");
        assert!(b.delay() <= 2, "{b:?}");
        right.push(a.wheel_scale[1]);
        // The same world index draws the same values.
        assert_eq!(World::with_index(&sc, w).unwrap().actuation(0), Some(a));
    }
    right.sort_by(f32::total_cmp);
    assert!(right[15] - right[0] > 0.03, "{right:?}");
}
