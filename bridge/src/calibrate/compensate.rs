//! `[rig] compensate`: robots that differ, driven and read as the scenario's nominal robot. A file of
//! identified values (`colcos rig identify`'s `[[robot]]` entries) says how each robot's wheels and
//! colour sensors depart from the model; the live loop sends each robot its command divided by its
//! wheel scales and hands the host its counts mapped back through its sensor gain and offset, so a
//! policy trained on the nominal robot meets robots that answer as that robot does. Motor lags and
//! command latencies cannot be undone by scaling and stay as they are.
use super::CalibrationError;
use colcos_sim::behaviour::WheelCommand;
use colcos_sim::scenario::individual::undo_sensor_gain;
use colcos_sim::scenario::{Individual, IndividualFile};
use std::path::Path;

/// Each robot's identified wheel scales and sensor gain and offset, to be undone.
#[derive(Clone, Debug)]
pub struct Compensation {
    robots: Vec<Individual>,
    /// The robots' top wheel speed, m/s: a compensated command is kept within it.
    max_wheel_speed: f32,
}

impl Compensation {
    /// Reads `path` for a rig of `robots` robots whose top wheel speed is `max_wheel_speed`; a robot
    /// the file leaves out is taken as nominal (sent and read unchanged).
    pub fn load(
        path: &Path,
        robots: usize,
        max_wheel_speed: f32,
    ) -> Result<Compensation, CalibrationError> {
        let file = IndividualFile::load(path).map_err(|e| CalibrationError::file(path, e))?;
        let robots = file
            .resolve(robots)
            .map_err(|e| CalibrationError::file(path, e))?;
        Ok(Compensation {
            robots,
            max_wheel_speed: max_wheel_speed.abs(),
        })
    }

    /// What robot `i` is sent so that its wheels turn as `cmd` asks of the nominal robot: each
    /// wheel's speed (within the top speed, as the nominal robot takes it) divided by its scale.
    /// Where a slow wheel would need more than the top speed, both wheels are scaled back together:
    /// the robot keeps the commanded curvature and gives up speed (clamping the slow wheel alone
    /// would turn a robot told to drive straight at full speed).
    pub fn command(&self, i: usize, cmd: WheelCommand) -> WheelCommand {
        let Some(r) = self.robots.get(i) else {
            return cmd;
        };
        let max = self.max_wheel_speed;
        let left = cmd.left.clamp(-max, max) / r.wheel_scale[0];
        let right = cmd.right.clamp(-max, max) / r.wheel_scale[1];
        let largest = left.abs().max(right.abs());
        let back = if largest > max { max / largest } else { 1.0 };
        WheelCommand::new(left * back, right * back)
    }

    /// Robot `i`'s own colour counts as the nominal sensor would read them: `(count - offset) /
    /// gain`, rounded, within the sensor's `0..=65535`.
    pub fn counts(&self, i: usize, mut counts: [[u16; 3]; 4]) -> [[u16; 3]; 4] {
        let Some(r) = self.robots.get(i) else {
            return counts;
        };
        if r.senses_nominally() {
            return counts;
        }
        undo_sensor_gain(&mut counts, r.sensor_gain, r.sensor_offset);
        counts
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use colcos_sim::scenario::individual::apply_sensor_gain;

    fn fit(text: &str, robots: usize) -> Compensation {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("fit.toml");
        std::fs::write(&path, text).unwrap();
        Compensation::load(&path, robots, 0.2).unwrap()
    }

    /// A slow wheel is sent proportionally more; where that would pass the top speed both wheels
    /// are scaled back together, so the robot's wheels still turn alike (straight ahead) at a lower
    /// speed. A robot the file leaves out, and one beyond the rig's robots, are sent the command.
    #[test]
    fn wheel_commands_are_divided_by_the_wheel_scales_keeping_the_curvature() {
        let c = fit("[[robot]]\nindex = 1\nwheel_scale = [0.8, 1.25]\n", 3);
        let cmd = WheelCommand::new(0.1, -0.1);
        assert_eq!(c.command(0, cmd), cmd);
        let sent = c.command(1, cmd);
        assert!((sent.left - 0.125).abs() < 1e-6 && (sent.right + 0.08).abs() < 1e-6);
        // Straight ahead at 0.18 m/s: the slow wheel would need 0.225, beyond the 0.2 it can be sent.
        let sent = c.command(1, WheelCommand::new(0.18, 0.18));
        assert!((sent.left - 0.2).abs() < 1e-6, "{sent:?}");
        let turns = [sent.left * 0.8, sent.right * 1.25];
        assert!(
            (turns[0] - turns[1]).abs() < 1e-6 && turns[0] < 0.18,
            "{turns:?}"
        );
        // A command beyond the top speed counts as the top speed, as the nominal robot takes it.
        let top = c.command(1, WheelCommand::new(0.2, 0.2));
        assert_eq!(c.command(1, WheelCommand::new(0.5, 0.5)), top);
        assert_eq!(c.command(7, cmd), cmd);
    }

    /// Counts that went through a robot's gain and offset (as the simulator's and the twin's robots
    /// read) come back as the nominal sensor's, to the rounding of the forward map.
    #[test]
    fn counts_through_a_gain_and_offset_come_back_as_the_nominal_sensors() {
        let c = fit(
            "[[robot]]\nindex = 0\nsensor_gain = 0.7\nsensor_offset = 40.0\n",
            2,
        );
        let nominal: [[u16; 3]; 4] =
            std::array::from_fn(|s| std::array::from_fn(|ch| (300 * s + 97 * ch + 11) as u16));
        let mut raw = nominal;
        apply_sensor_gain(&mut raw, 0.7, 40.0);
        let back = c.counts(0, raw);
        for (b, n) in back.iter().flatten().zip(nominal.iter().flatten()) {
            assert!((*b as i32 - *n as i32).abs() <= 1, "{b} against {n}");
        }
        assert_eq!(c.counts(1, raw), raw);
        // Below the offset: the nominal sensor reads nothing, not a wrapped count.
        assert_eq!(c.counts(0, [[10; 3]; 4]), [[0; 3]; 4]);
    }

    /// A file that is not one of per-robot values, or names a robot the rig lacks, is refused with
    /// the file's path and the key at fault.
    #[test]
    fn a_bad_file_is_refused_naming_it_and_the_key() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("fit.toml");
        std::fs::write(&path, "[[robot]]\nindex = 5\nwheel_scale = [1.0, 1.0]\n").unwrap();
        let e = Compensation::load(&path, 3, 0.2).unwrap_err().to_string();
        assert!(
            e.contains("fit.toml") && e.contains("robot[0].index"),
            "{e}"
        );
        std::fs::write(&path, "[[robot]]\nindex = 0\nwheel_scale = [0.0, 1.0]\n").unwrap();
        let e = Compensation::load(&path, 3, 0.2).unwrap_err().to_string();
        assert!(e.contains("robot[0].wheel_scale"), "{e}");
        let e = Compensation::load(&dir.path().join("missing.toml"), 3, 0.2)
            .unwrap_err()
            .to_string();
        assert!(e.contains("missing.toml"), "{e}");
    }
}
