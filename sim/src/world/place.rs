//! Robots moved by hand at the start of an episode (a task's reset placing them): checked, moved at
//! rest, tracked and sensed where they now are.
use super::World;
use crate::robot::Pose;

impl World {
    /// Moves each robot `i` of `placed` to its pose, as if it had started there: the tracker starts
    /// over from the new poses and every robot's observation is taken afresh. A pose must be finite
    /// and hold the robot's disc inside the arena, clear of the obstacles and of every other robot;
    /// otherwise nothing moves and the error names the robot and what is wrong. What the world
    /// did as it was built stays (deposits laid where the robots first stood); the pheromone
    /// sources that follow robots move to them at the next step.
    pub fn place_robots(&mut self, placed: &[(usize, Pose)]) -> Result<(), String> {
        let n = self.robot_count();
        let r = self.robots.physics.radius();
        let size = self.arena;
        let mut poses = self.robots.poses().to_vec();
        for &(i, p) in placed {
            let at = format!("robot {i} at [{}, {}, {}]", p.pos.x, p.pos.y, p.heading);
            if i >= n {
                return Err(format!(
                    "robot {i} does not exist (the world has {n} robots)"
                ));
            }
            if !(p.pos.is_finite() && p.heading.is_finite()) {
                return Err(format!("{at}: a pose must be finite"));
            }
            let inside =
                p.pos.x >= r && p.pos.y >= r && p.pos.x <= size.x - r && p.pos.y <= size.y - r;
            if !inside || !self.obstacles().holds(p.pos, r) {
                return Err(format!(
                    "{at}: a robot of radius {r} m there lies outside the arena ({} x {} m)",
                    size.x, size.y
                ));
            }
            if let Some(o) = self.obstacles().overlapping(p.pos, r, 0.0) {
                return Err(format!(
                    "{at}: a robot of radius {r} m there overlaps obstacle {o}"
                ));
            }
            poses[i] = p;
        }
        // Every placed robot clear of every other robot, placed or not.
        for &(i, p) in placed {
            let hit = (0..n).find(|&j| j != i && poses[j].pos.distance(p.pos) < 2.0 * r);
            if let Some(j) = hit {
                let q = poses[j].pos;
                return Err(format!(
                    "robot {i} at [{}, {}]: overlaps robot {j} at [{}, {}] (robots of radius {r} m)",
                    p.pos.x, p.pos.y, q.x, q.y
                ));
            }
        }
        for &(i, p) in placed {
            self.robots.physics.set_pose(i, p);
        }
        let poses = self.robots.poses();
        self.tracking.restart(self.time, poses);
        self.observe();
        Ok(())
    }
}
