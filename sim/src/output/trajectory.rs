//! The trajectory log: one CSV row per robot and logged tick, appended and flushed as the run goes,
//! so a killed run keeps every complete row.
use crate::error::{Result, SimError};
use crate::world::World;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::Path;

/// Column names of the trajectory CSV, in order.
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
}

impl TrajectoryLog {
    /// Creates (truncates) the log and writes the header.
    pub fn create(path: &Path) -> Result<Self> {
        let file = File::create(path)
            .map_err(|e| SimError::io(format!("creating {}", path.display()), e))?;
        let mut log = TrajectoryLog {
            out: BufWriter::with_capacity(1 << 20, file),
            path: path.display().to_string(),
            line: String::new(),
        };
        let h = header();
        log.write_str(&h)?;
        log.write_str("\n")?;
        log.flush()?;
        Ok(log)
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
        use std::fmt::Write as _;
        let (poses, tracked, obs) = (world.poses(), world.tracked(), world.observations());
        for i in 0..world.robot_count() {
            let (p, t, o, cmd) = (&poses[i], &tracked[i], &obs[i], world.robots()[i].command);
            let l = &mut self.line;
            l.clear();
            let _ = write!(
                l,
                "{},{:.2},{},{},{:.5},{:.5},{:.4},{:.5},{:.5},{:.4},{},{:.4},{:.4}",
                world.tick(),
                world.time(),
                i,
                world.role(i),
                p.pos.x,
                p.pos.y,
                p.heading,
                t.pose.pos.x,
                t.pose.pos.y,
                t.pose.heading,
                t.seen as u8,
                cmd.left,
                cmd.right
            );
            for counts in &o.counts {
                for c in counts {
                    let _ = write!(l, ",{c}");
                }
            }
            for b in &o.bumpers {
                let _ = write!(l, ",{b:.3}");
            }
            l.push('\n');
            let line = std::mem::take(&mut self.line);
            let res = self.write_str(&line);
            self.line = line;
            res?;
        }
        // Rows reach the file whole: the buffer is flushed only at a tick boundary.
        self.flush()
    }
}
