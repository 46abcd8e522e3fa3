//! `[sensor] per_robot` reaches the batched environment by the same scenario path as `colcos run`:
//! every world of a `VecEnv` reads the screen through each robot's fitted sensors from the file.
use colcos_env::{EnvConfig, ScenarioSource, VecEnv};
use colcos_sim::sensors::{ColourCalibration, RobotColour, SensorFit};

/// Robot `r` (radio r + 1): gain and dark counts growing with r, its own gamma and crosstalk.
fn calibration(robots: usize) -> ColourCalibration {
    let robots = (0..robots)
        .map(|r| {
            let g = 600.0 + 500.0 * r as f64;
            let x = 0.04 * r as f64;
            let crosstalk = [[1.0, x, 0.02], [0.05, 1.0, x], [x, 0.1, 1.0]];
            let fit = SensorFit {
                gamma: 1.8 + 0.15 * r as f64,
                dark: [10.0 + 20.0 * r as f64, 30.0, 15.0 + 5.0 * r as f64],
                matrix: crosstalk.map(|row| row.map(|v| v * g * 24.0)),
                gain: g,
                crosstalk,
                rms_counts: 5.0,
            };
            RobotColour {
                radio_id: r as u8 + 1,
                sensors: [fit; 4],
            }
        })
        .collect();
    ColourCalibration::new("2026-11-24T00:00:00Z".into(), 24.0, robots, 6.0)
}

fn config(extra: &str) -> EnvConfig {
    let mut cfg = EnvConfig::new("aggregation");
    let text = colcos_env::task::aggregation::DEFAULT_SCENARIO;
    cfg.scenario = ScenarioSource::Text(format!("{text}\n{extra}"));
    cfg.num_envs = 3;
    cfg
}

#[test]
fn every_world_of_the_batch_reads_through_the_robots_own_sensors() {
    let path = std::env::temp_dir().join(format!("colcos-per-robot-{}.json", std::process::id()));
    let cal = calibration(5);
    cal.save(&path).unwrap();
    let rig = format!(
        "[rig]\ncolour_calibration = {:?}\n",
        path.display().to_string()
    );
    let mut nominal = VecEnv::new(&config(&format!("[sensor]\nnoise = 0.0\n{rig}"))).unwrap();
    let mut own = VecEnv::new(&config(&format!(
        "[sensor]\nnoise = 0.0\nper_robot = true\n{rig}"
    )))
    .unwrap();
    nominal.reset(Some(4), None).unwrap();
    own.reset(Some(4), None).unwrap();
    let mut checked = 0;
    for e in 0..3 {
        let (n, w) = (nominal.world(e).unwrap(), own.world(e).unwrap());
        assert_eq!(n.poses(), w.poses(), "world {e}: the same placement");
        for (r, robot) in cal.robots.iter().enumerate() {
            assert!(w.robot_sensors(r).is_some() && n.robot_sensors(r).is_none());
            for k in 0..4 {
                let levels = n.observations()[r].intensity[k].map(|v| v as f64 * 255.0);
                let want = robot.sensors[k].predict(levels);
                let got = w.observations()[r].counts[k];
                for c in 0..3 {
                    assert!(
                        (got[c] as f64 - want[c]).abs() < 2.0 + 0.005 * want[c],
                        "world {e} robot {r} sensor {k}: {got:?} against the file's {want:?}"
                    );
                }
                checked += 1;
            }
        }
    }
    assert_eq!(checked, 3 * 5 * 4);
    // Robots differ as the file says: each reads its own dark counts on the red channel at least.
    let w = own.world(0).unwrap();
    let red: Vec<u16> = (0..5).map(|r| w.observations()[r].counts[0][0]).collect();
    assert!(red.windows(2).all(|p| p[0] != p[1]), "{red:?}");
    let _ = std::fs::remove_file(&path);
}
