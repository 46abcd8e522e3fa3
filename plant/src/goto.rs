//! The go-to controller a plant's `reset` drives the real (or twin) robots with to the episode's start
//! poses: turn toward the target, drive to it slowing down as it nears, turn to the target heading.
//! Collision-aware by priority: a robot waits while a lower-numbered one is in its way, so two robots
//! never wait on each other.
use colcos_sim::behaviour::WheelCommand;
use colcos_sim::robot::Pose;
use glam::Vec2;
use std::f32::consts::{PI, TAU};

#[derive(Clone, Copy, Debug)]
pub struct GoTo {
    /// Largest wheel speed used, m/s.
    pub max_speed: f32,
    /// Distance between the wheels, m.
    pub wheel_base: f32,
    /// Robot radius, m.
    pub radius: f32,
    /// A robot within this distance of its target position has arrived there, m.
    pub tolerance: f32,
    /// ... and within this of its target heading, rad.
    pub heading_tolerance: f32,
}

impl GoTo {
    /// A controller for robots of `radius` and `wheel_base`, at most `max_speed`.
    pub fn new(max_speed: f32, wheel_base: f32, radius: f32) -> GoTo {
        GoTo {
            max_speed,
            wheel_base,
            radius,
            tolerance: 0.01,
            heading_tolerance: 0.1,
        }
    }

    /// Whether robot `i` at `pose` is at `target`.
    pub fn arrived(&self, pose: &Pose, target: &Pose) -> bool {
        pose.pos.distance(target.pos) <= self.tolerance
            && wrap(target.heading - pose.heading).abs() <= self.heading_tolerance
    }

    /// The command that brings robot `i` (of `poses`) toward `targets[i]`, and whether it is there.
    /// A robot waits for a lower-numbered one that is still moving in its way, and steers around one
    /// that is parked (or higher-numbered, which waits for it).
    pub fn command(&self, i: usize, poses: &[Pose], targets: &[Pose]) -> (WheelCommand, bool) {
        let (pose, target) = (poses[i], targets[i]);
        let to = target.pos - pose.pos;
        let dist = to.length();
        let (v, w) = if dist > self.tolerance {
            let mut bearing = wrap(to.y.atan2(to.x) - pose.heading);
            let ahead = Vec2::from_angle(pose.heading);
            let mut wait = false;
            for (j, q) in poses.iter().enumerate().filter(|(j, _)| *j != i) {
                let d = q.pos - pose.pos;
                // In the way: close, ahead, and nearer than the target.
                if d.length() > 3.0 * self.radius || d.dot(ahead) <= 0.0 || d.length() > dist {
                    continue;
                }
                let parked = targets.get(j).is_none_or(|t| self.arrived(q, t));
                if j < i && !parked {
                    wait = true;
                } else {
                    // Turn away from its side.
                    let side = ahead.perp_dot(d).signum();
                    bearing = wrap(bearing - side * 0.9);
                }
            }
            // Turn in place while far off course or waiting for a robot in the way.
            if bearing.abs() > 0.6 || wait {
                (0.0, 4.0 * bearing)
            } else {
                (
                    (2.0 * dist).min(self.max_speed) * bearing.cos(),
                    4.0 * bearing,
                )
            }
        } else {
            let err = wrap(target.heading - pose.heading);
            if err.abs() <= self.heading_tolerance {
                return (WheelCommand::STOP, true);
            }
            (0.0, 4.0 * err)
        };
        let half = 0.5 * w * self.wheel_base;
        let (left, right) = (v - half, v + half);
        // Scaled together so that the turn keeps its radius when a wheel hits the limit.
        let scale = (self.max_speed / left.abs().max(right.abs()).max(1e-9)).min(1.0);
        (
            WheelCommand {
                left: left * scale,
                right: right * scale,
            },
            false,
        )
    }
}

/// `a` wrapped to (-pi, pi].
fn wrap(a: f32) -> f32 {
    let a = a.rem_euclid(TAU);
    if a > PI { a - TAU } else { a }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Differential-drive kinematics, exact for one step at constant wheel speeds.
    fn drive(p: &mut Pose, c: WheelCommand, wheel_base: f32, dt: f32) {
        let v = 0.5 * (c.left + c.right);
        let w = (c.right - c.left) / wheel_base;
        let h = p.heading + 0.5 * w * dt;
        p.pos += Vec2::from_angle(h) * v * dt;
        p.heading = wrap(p.heading + w * dt);
    }

    #[test]
    fn robots_reach_their_targets_from_anywhere_without_colliding() {
        let g = GoTo::new(0.1, 0.034, 0.02);
        let mut poses = vec![
            Pose::new(0.1, 0.1, 0.0),
            Pose::new(0.5, 0.4, 3.0),
            Pose::new(0.9, 0.1, -1.0),
        ];
        // Targets crossing each other's paths.
        let targets = [
            Pose::new(0.9, 0.3, 1.5),
            Pose::new(0.1, 0.1, -2.0),
            Pose::new(0.3, 0.4, 0.5),
        ];
        let mut closest = f32::INFINITY;
        let mut arrived = [false; 3];
        for _ in 0..5000 {
            let cmds: Vec<_> = (0..3).map(|i| g.command(i, &poses, &targets)).collect();
            for (i, (c, done)) in cmds.iter().enumerate() {
                arrived[i] = *done;
                drive(&mut poses[i], *c, g.wheel_base, 0.02);
            }
            for i in 0..3 {
                for j in 0..i {
                    closest = closest.min(poses[i].pos.distance(poses[j].pos));
                }
            }
            if arrived.iter().all(|a| *a) {
                break;
            }
        }
        assert!(arrived.iter().all(|a| *a), "{poses:?}");
        for (p, t) in poses.iter().zip(&targets) {
            assert!(p.pos.distance(t.pos) <= g.tolerance, "{p:?} {t:?}");
            assert!(wrap(p.heading - t.heading).abs() <= g.heading_tolerance);
        }
        assert!(closest > 1.5 * g.radius, "robots came {closest} m close");
    }

    #[test]
    fn a_robot_steers_around_one_parked_in_its_way() {
        let g = GoTo::new(0.1, 0.034, 0.02);
        // Robot 0 is parked on the straight line from robot 1 to its target.
        let mut poses = vec![Pose::new(0.5, 0.3, 0.0), Pose::new(0.2, 0.3, 0.0)];
        let targets = [Pose::new(0.5, 0.3, 0.0), Pose::new(0.8, 0.3, 0.0)];
        let mut closest = f32::INFINITY;
        let mut done = false;
        for _ in 0..3000 {
            let (c, arrived) = g.command(1, &poses, &targets);
            done = arrived;
            if done {
                break;
            }
            drive(&mut poses[1], c, g.wheel_base, 0.02);
            closest = closest.min(poses[0].pos.distance(poses[1].pos));
        }
        assert!(done, "{poses:?}");
        assert!(closest > 1.5 * g.radius, "came {closest} m close");
    }

    #[test]
    fn commands_stay_within_the_speed_limit() {
        let g = GoTo::new(0.05, 0.034, 0.02);
        let poses = [Pose::new(0.0, 0.0, 0.0)];
        for k in 0..64 {
            let a = k as f32 * 0.1;
            let (c, _) = g.command(0, &poses, &[Pose::new(a.cos(), a.sin(), a)]);
            assert!(
                c.left.abs() <= 0.05 + 1e-6 && c.right.abs() <= 0.05 + 1e-6,
                "{c:?}"
            );
        }
    }
}
