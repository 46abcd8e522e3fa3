//! The trajectory log: one CSV row per robot and logged tick, appended and flushed as the run goes,
//! so a killed run keeps every complete row. Where robots may lay pheromone by action
//! (`[[robots]] deposit_actions`, emitters with `when = "action"`), each such pheromone gets a
//! `lay_<name>` column: the robot's action for it at that tick (a fraction of a trail's `max_rate`; an
//! emitter's switch), 0 for robots whose group cannot lay it.
use super::fixed::{push_digits, push_fixed};
use crate::error::{Result, SimError};
use crate::scenario::RobotGroupSpec;
use crate::world::World;
use rayon::prelude::*;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::Path;

/// The pheromones robots may lay by action, one log column each, and where each group's robots keep
/// that pheromone's fraction among their own deposit actions.
#[derive(Clone, Debug, Default)]
pub struct LayColumns {
    names: Vec<String>,
    /// Per group, per column: the index into the robot's deposit actions, if its group lays it.
    slots: Vec<Vec<Option<usize>>>,
}

impl LayColumns {
    /// The columns of the robot groups `groups` (none where no group has deposit actions).
    pub fn of(groups: &[RobotGroupSpec]) -> Self {
        let mut names: Vec<String> = Vec::new();
        for name in groups.iter().flat_map(|g| g.action_pheromones()) {
            if !names.iter().any(|n| n == name) {
                names.push(name.to_string());
            }
        }
        let slots = groups
            .iter()
            .map(|g| {
                let find = |name: &String| g.action_pheromones().position(|p| p == name);
                names.iter().map(find).collect()
            })
            .collect();
        LayColumns { names, slots }
    }

    pub fn is_empty(&self) -> bool {
        self.names.is_empty()
    }
}

/// Column names of the trajectory CSV of a scenario whose robots lay by action as `lay` says.
pub fn header_with(lay: &LayColumns) -> String {
    let mut h = header();
    for name in &lay.names {
        h.push_str(",lay_");
        h.push_str(name);
    }
    h
}

/// Column names of the trajectory CSV, in order (without `lay_` columns).
pub fn header() -> String {
    let mut cols: Vec<String> = [
        "tick",
        "time",
        "robot",
        "role",
        "x",
        "y",
        "heading",
        "tracked_x",
        "tracked_y",
        "tracked_heading",
        "tracked_seen",
        "cmd_left",
        "cmd_right",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    for n in 0..4 {
        for c in ["r", "g", "b"] {
            cols.push(format!("s{n}_{c}"));
        }
    }
    cols.extend(["bump_fl", "bump_f", "bump_fr"].map(String::from));
    cols.join(",")
}

pub struct TrajectoryLog {
    out: BufWriter<File>,
    path: String,
    line: String,
    /// Each robot's last command and group, copied per tick into buffers kept between ticks (the
    /// robots themselves cannot be shared across the formatting threads).
    commands: Vec<crate::behaviour::WheelCommand>,
    groups: Vec<usize>,
    lay: LayColumns,
}

impl TrajectoryLog {
    /// Creates (truncates) the log of a scenario with robot groups `groups` and writes the header.
    pub fn create(path: &Path, groups: &[RobotGroupSpec]) -> Result<Self> {
        let file = File::create(path)
            .map_err(|e| SimError::io(format!("creating {}", path.display()), e))?;
        let mut log = TrajectoryLog {
            out: BufWriter::with_capacity(1 << 20, file),
            path: path.display().to_string(),
            line: String::new(),
            commands: Vec::new(),
            groups: Vec::new(),
            lay: LayColumns::of(groups),
        };
        let h = header_with(&log.lay);
        log.write_str(&h)?;
        log.write_str("\n")?;
        log.flush()?;
        Ok(log)
    }

    /// Whether the log has `lay_` columns (then [`TickRows::lay`] must hold every robot's deposit
    /// actions).
    pub fn has_lay_columns(&self) -> bool {
        !self.lay.is_empty()
    }

    fn write_str(&mut self, s: &str) -> Result<()> {
        self.out
            .write_all(s.as_bytes())
            .map_err(|e| SimError::io(format!("writing {}", self.path), e))
    }

    fn flush(&mut self) -> Result<()> {
        self.out
            .flush()
            .map_err(|e| SimError::io(format!("writing {}", self.path), e))
    }

    /// Appends one row per robot for the world's current tick and flushes them to the file.
    pub fn record(&mut self, world: &World) -> Result<()> {
        // Taken out of `self` while the rows borrow them (writing needs `&mut self`), then put back.
        let (mut commands, mut groups) = (
            std::mem::take(&mut self.commands),
            std::mem::take(&mut self.groups),
        );
        commands.clear();
        commands.extend(world.robots().iter().map(|r| r.command));
        groups.clear();
        groups.extend(world.robots().iter().map(|r| r.group));
        let lay: Vec<&[f32]> = if self.lay.is_empty() {
            Vec::new()
        } else {
            (0..groups.len())
                .map(|i| world.deposit_actions(i))
                .collect()
        };
        let rows = TickRows {
            tick: world.tick(),
            time: world.time(),
            poses: world.poses(),
            tracked: world.tracked(),
            obs: world.observations(),
            commands: &commands,
            groups: &groups,
            group_specs: &world.scenario().spec.robots,
            lay: &lay,
        };
        let latest = world.tracked_frame_stamp();
        let written = self
            .write_rows(&rows, rows.poses.len(), latest)
            .and_then(|()| self.flush());
        (self.commands, self.groups) = (commands, groups);
        written
    }

    /// Appends one row per robot of `rows` and flushes them: for a host without a simulated world
    /// (the hardware bridge, whose `poses` are the tracked ones as it used them). `tracked_seen` is
    /// each tracked pose's own `seen`.
    pub fn record_rows(&mut self, rows: &TickRows) -> Result<()> {
        self.write_rows(rows, rows.poses.len(), None)?;
        // Rows reach the file whole: the buffer is flushed only at a tick boundary.
        self.flush()
    }

    /// Formats and writes the `n` rows of one tick, in robot order; `latest`: the stamp of the
    /// tracker's newest frame (see [`TickRows::push_row`]).
    fn write_rows(&mut self, rows: &TickRows, n: usize, latest: Option<f32>) -> Result<()> {
        if n < 2 * ROWS_PER_CHUNK {
            let mut text = std::mem::take(&mut self.line);
            text.clear();
            (0..n).for_each(|i| rows.push_row(&mut text, i, latest, &self.lay));
            let res = self.write_str(&text);
            self.line = text;
            res?;
        } else {
            // A large swarm's rows are formatted in parallel chunks and written in robot order.
            let chunks: Vec<String> = (0..n.div_ceil(ROWS_PER_CHUNK))
                .into_par_iter()
                .map(|c| {
                    let lay = &self.lay;
                    let mut text = String::with_capacity(ROWS_PER_CHUNK * 160);
                    (c * ROWS_PER_CHUNK..((c + 1) * ROWS_PER_CHUNK).min(n))
                        .for_each(|i| rows.push_row(&mut text, i, latest, lay));
                    text
                })
                .collect();
            for text in &chunks {
                self.write_str(text)?;
            }
        }
        Ok(())
    }
}

/// Robots whose rows one parallel task formats.
const ROWS_PER_CHUNK: usize = 512;

/// What the rows of one tick are made of, one entry per robot in each slice (the world itself is not
/// shared across the formatting threads).
pub struct TickRows<'a> {
    pub tick: u64,
    /// s.
    pub time: f32,
    pub poses: &'a [crate::robot::Pose],
    pub tracked: &'a [crate::tracker::TrackedPose],
    pub obs: &'a [crate::behaviour::Observation],
    pub commands: &'a [crate::behaviour::WheelCommand],
    /// Each robot's group, an index into `group_specs` (its role is written).
    pub groups: &'a [usize],
    pub group_specs: &'a [crate::scenario::RobotGroupSpec],
    /// Each robot's deposit actions (fractions of their `max_rate`); empty where no robot lays by
    /// action.
    pub lay: &'a [&'a [f32]],
}

impl TickRows<'_> {
    /// Appends robot `i`'s row, newline included. `tracked_seen` is 1 when the tracked pose comes from
    /// the tracker's newest frame (stamped `latest`), 0 when the robot dropped out of it and keeps an
    /// older pose; without `latest`, the pose's own `seen`.
    fn push_row(&self, l: &mut String, i: usize, latest: Option<f32>, lay: &LayColumns) {
        let (p, t, o, cmd) = (
            &self.poses[i],
            &self.tracked[i],
            &self.obs[i],
            self.commands[i],
        );
        push_digits(l, self.tick, 1);
        l.push(',');
        push_fixed(l, self.time, 2);
        l.push(',');
        push_digits(l, i as u64, 1);
        l.push(',');
        l.push_str(&self.group_specs[self.groups[i]].role);
        l.push(',');
        for (k, (value, decimals)) in [
            (p.pos.x, 5),
            (p.pos.y, 5),
            (p.heading, 4),
            (t.pose.pos.x, 5),
            (t.pose.pos.y, 5),
            (t.pose.heading, 4),
        ]
        .into_iter()
        .enumerate()
        {
            if k > 0 {
                l.push(',');
            }
            push_fixed(l, value, decimals);
        }
        let seen = t.seen && latest.is_none_or(|s| t.stamp == s);
        l.push_str(if seen { ",1," } else { ",0," });
        push_fixed(l, cmd.left, 4);
        l.push(',');
        push_fixed(l, cmd.right, 4);
        for counts in &o.counts {
            for &c in counts {
                l.push(',');
                push_digits(l, u64::from(c), 1);
            }
        }
        for &b in &o.bumpers {
            l.push(',');
            push_fixed(l, b, 3);
        }
        if let Some(slots) = lay.slots.get(self.groups[i]).filter(|_| !lay.is_empty()) {
            let mine = self.lay.get(i).copied().unwrap_or(&[]);
            for slot in slots {
                l.push(',');
                push_fixed(l, slot.and_then(|k| mine.get(k)).copied().unwrap_or(0.0), 3);
            }
        }
        l.push('\n');
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::Scenario;

    /// `tracked_seen` is 0 exactly when a robot dropped out of the tracker's newest frame, and
    /// `tracked_heading` stays in (-pi, pi] with heading noise.
    #[test]
    fn the_log_shows_dropouts_and_wrapped_headings() {
        let text = "duration = 1.0\n[tracker]\ndropout = 0.4\nheading_noise = 0.5\n\
                    [[robots]]\ncount = 6\nbehaviour = \"avoid\"\n";
        let sc = Scenario::from_toml_str(text, ".").unwrap();
        let mut world = World::new(&sc).unwrap();
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("trajectory.csv");
        let mut log = TrajectoryLog::create(&path, &sc.spec.robots).unwrap();
        let mut expected = Vec::new();
        for _ in 0..50 {
            world.step();
            log.record(&world).unwrap();
            let latest = world.tracked_frame_stamp().unwrap();
            expected.extend(world.tracked().iter().map(|t| u8::from(t.stamp == latest)));
        }
        drop(log);
        let text = std::fs::read_to_string(&path).unwrap();
        let cols: Vec<&str> = text.lines().next().unwrap().split(',').collect();
        let at = |name: &str| cols.iter().position(|c| *c == name).unwrap();
        let (seen_col, heading_col) = (at("tracked_seen"), at("tracked_heading"));
        let rows: Vec<Vec<&str>> = text
            .lines()
            .skip(1)
            .map(|l| l.split(',').collect())
            .collect();
        let seen: Vec<u8> = rows.iter().map(|r| r[seen_col].parse().unwrap()).collect();
        assert_eq!(seen, expected);
        let dropped = seen.iter().filter(|&&s| s == 0).count();
        assert!(
            dropped > 20 && dropped < seen.len() - 20,
            "{dropped} of {}",
            seen.len()
        );
        for r in &rows {
            let h: f32 = r[heading_col].parse().unwrap();
            assert!(
                h.abs() <= std::f32::consts::PI + 1e-4,
                "tracked heading {h}"
            );
        }
    }
}
