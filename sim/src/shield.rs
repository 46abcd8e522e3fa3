//! The safety shield: the same last word on every wheel command in every plant (simulator, twin, rig),
//! so that training sees what deployment does. It caps the wheel speeds and keeps a robot inside
//! virtual walls a margin inside the arena: a command that would carry the robot past a wall within a
//! short horizon loses its forward part and turns in place instead.
use crate::behaviour::WheelCommand;
use crate::robot::Pose;
use glam::Vec2;
use serde::{Deserialize, Serialize};

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ShieldParams {
    /// Largest wheel speed let through, m/s.
    pub max_wheel_speed: f32,
    /// Distance of the virtual walls inside the arena's edges, m (measured from the robot's centre).
    pub margin: f32,
    /// How far ahead a command is followed to see whether it crosses a virtual wall, s.
    pub horizon: f32,
}

impl Default for ShieldParams {
    fn default() -> Self {
        ShieldParams {
            max_wheel_speed: 0.35,
            margin: 0.03,
            horizon: 0.15,
        }
    }
}

/// What the shield changed in one command.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Intervention {
    /// The cap lowered a wheel speed below what the robot itself would have driven (a command beyond
    /// the robot's own `max_wheel_speed` is clamped by the robot anyway: that is no intervention).
    pub capped: bool,
    /// The command would have crossed a virtual wall.
    pub walled: bool,
}

impl Intervention {
    pub fn any(&self) -> bool {
        self.capped || self.walled
    }
}

/// Running counts of interventions.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct ShieldCounts {
    pub capped: u64,
    pub walled: u64,
}

impl ShieldCounts {
    pub fn add(&mut self, i: Intervention) {
        self.capped += i.capped as u64;
        self.walled += i.walled as u64;
    }
}

#[derive(Clone, Copy, Debug)]
pub struct Shield {
    pub params: ShieldParams,
    arena: Vec2,
    robot_max_wheel_speed: f32,
}

impl Shield {
    /// A shield for an arena of `arena` m and robots whose wheels reach `robot_max_wheel_speed` m/s.
    pub fn new(params: ShieldParams, arena: Vec2, robot_max_wheel_speed: f32) -> Shield {
        Shield {
            params,
            arena,
            robot_max_wheel_speed: robot_max_wheel_speed.abs(),
        }
    }

    /// The command a robot at `pose` may take in place of `cmd` (a non-finite command is a stop).
    pub fn apply(&self, pose: &Pose, cmd: WheelCommand) -> (WheelCommand, Intervention) {
        self.apply_facing(pose, pose.forward(), cmd)
    }

    /// [`Self::apply`] for a robot whose heading vector `forward` (`pose.forward()`) is known.
    pub fn apply_facing(
        &self,
        pose: &Pose,
        forward_dir: Vec2,
        cmd: WheelCommand,
    ) -> (WheelCommand, Intervention) {
        let mut out = Intervention::default();
        if !(cmd.left.is_finite() && cmd.right.is_finite()) {
            return (WheelCommand::STOP, out);
        }
        let cap = self.params.max_wheel_speed.max(0.0);
        let (left, right) = (cmd.left.clamp(-cap, cap), cmd.right.clamp(-cap, cap));
        let robot = self.robot_max_wheel_speed;
        out.capped =
            left != cmd.left.clamp(-robot, robot) || right != cmd.right.clamp(-robot, robot);
        let forward = 0.5 * (left + right);
        let ahead = pose.pos + forward_dir * forward * self.params.horizon;
        let m = self.params.margin.max(0.0);
        let (lo, hi) = (Vec2::splat(m), self.arena - Vec2::splat(m));
        // Which way is inside, per axis, when the command heads out past a virtual wall.
        let inward = |now: f32, then: f32, lo: f32, hi: f32| {
            if then < lo && then < now {
                1.0
            } else if then > hi && then > now {
                -1.0
            } else {
                0.0
            }
        };
        let inside = Vec2::new(
            inward(pose.pos.x, ahead.x, lo.x, hi.x),
            inward(pose.pos.y, ahead.y, lo.y, hi.y),
        );
        if inside != Vec2::ZERO {
            out.walled = true;
            // Keep the turn, drop the forward part. A turn slower than a quarter of the cap (a
            // behaviour steering by noise) could hold a robot facing the wall for seconds: it is
            // replaced by that speed toward the inside.
            let turn = 0.5 * (right - left);
            let least = 0.25 * cap;
            let turn = if turn.abs() >= least {
                turn
            } else {
                let motion = forward_dir * forward.signum();
                least.copysign(motion.perp_dot(inside))
            };
            return (
                WheelCommand {
                    left: -turn,
                    right: turn,
                },
                out,
            );
        }
        (WheelCommand { left, right }, out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn shield() -> Shield {
        Shield::new(ShieldParams::default(), Vec2::new(1.0, 0.5), 0.5)
    }

    #[test]
    fn speeds_are_capped_and_non_finite_commands_stop() {
        let (c, i) = shield().apply(
            &Pose::new(0.5, 0.25, 0.0),
            WheelCommand {
                left: 1.0,
                right: -0.1,
            },
        );
        assert_eq!(
            c,
            WheelCommand {
                left: 0.35,
                right: -0.1
            }
        );
        assert!(i.capped && !i.walled);
        let (c, i) = shield().apply(
            &Pose::new(0.5, 0.25, 0.0),
            WheelCommand {
                left: f32::NAN,
                right: 0.1,
            },
        );
        assert_eq!(c, WheelCommand::STOP);
        assert!(!i.any());
    }

    #[test]
    fn a_cap_at_the_robots_own_top_speed_is_no_intervention() {
        let s = Shield::new(ShieldParams::default(), Vec2::new(1.0, 0.5), 0.35);
        let fast = WheelCommand {
            left: 1.0,
            right: -1.0,
        };
        let (c, i) = s.apply(&Pose::new(0.5, 0.25, 0.0), fast);
        assert_eq!(c, WheelCommand::new(0.35, -0.35));
        assert!(!i.capped);
        // A robot that could drive faster than the cap is held back: that counts.
        let s = Shield::new(ShieldParams::default(), Vec2::new(1.0, 0.5), 0.4);
        assert!(s.apply(&Pose::new(0.5, 0.25, 0.0), fast).1.capped);
    }

    #[test]
    fn a_robot_driving_at_a_wall_turns_in_place_and_may_drive_away() {
        let s = shield();
        let fwd = WheelCommand {
            left: 0.3,
            right: 0.3,
        };
        // Heading +x, 2 cm from the right virtual wall: 0.3 m/s for 0.15 s crosses it.
        let near = Pose::new(0.95, 0.25, 0.0);
        let (c, i) = s.apply(&near, fwd);
        assert!(i.walled);
        assert_eq!(c.left, -c.right);
        // Facing away from the wall the same command passes.
        let away = Pose::new(0.95, 0.25, std::f32::consts::PI);
        assert_eq!(s.apply(&away, fwd), (fwd, Intervention::default()));
        // Far from the walls nothing changes.
        assert_eq!(s.apply(&Pose::new(0.5, 0.25, 0.0), fwd).0, fwd);
        // Reversing into the bottom wall is caught too.
        let (_, i) = s.apply(
            &Pose::new(0.5, 0.04, std::f32::consts::FRAC_PI_2),
            WheelCommand {
                left: -0.3,
                right: -0.3,
            },
        );
        assert!(i.walled);
    }

    /// A behaviour steering by noise at a wall turns toward the inside at a quarter of the cap, and
    /// keeps turning that way until it may drive again.
    #[test]
    fn a_robot_facing_a_wall_with_a_faint_turn_turns_away_at_the_least_speed() {
        let s = shield();
        let least = 0.25 * ShieldParams::default().max_wheel_speed;
        // Near the bottom wall, heading down and 0.2 rad toward -x: the short way to the inside is
        // clockwise, whatever the sign of the faint turn.
        let pose = Pose::new(0.5, 0.04, -std::f32::consts::FRAC_PI_2 - 0.2);
        for faint in [0.004, -0.004, 0.0] {
            let (c, i) = s.apply(&pose, WheelCommand::new(0.12 - faint, 0.12 + faint));
            assert!(i.walled);
            assert_eq!(c, WheelCommand::new(least, -least), "{faint}");
        }
        // Mirrored, counter-clockwise.
        let pose = Pose::new(0.5, 0.04, -std::f32::consts::FRAC_PI_2 + 0.2);
        let (c, _) = s.apply(&pose, WheelCommand::new(0.12, 0.12));
        assert_eq!(c, WheelCommand::new(-least, least));
        // Reversing into the wall: the back is what must turn away.
        let pose = Pose::new(0.5, 0.04, std::f32::consts::FRAC_PI_2 + 0.2);
        let (c, _) = s.apply(&pose, WheelCommand::new(-0.12, -0.12));
        assert_eq!(c, WheelCommand::new(-least, least));
        // A decisive turn is kept.
        let (c, _) = s.apply(&pose, WheelCommand::new(-0.3, 0.1));
        assert_eq!(c, WheelCommand::new(-0.2, 0.2));
        // Turned by the shield tick by tick (20 ms, the Colias wheel base), the robot leaves the
        // wall within a second.
        let wheel_base = crate::robot::ColiasParams::default().wheel_base;
        let mut p = Pose::new(0.5, 0.04, -std::f32::consts::FRAC_PI_2 - 0.05);
        for tick in 0.. {
            let (c, i) = s.apply(&p, WheelCommand::new(0.12, 0.121));
            if !i.walled {
                break;
            }
            assert!(tick < 50, "{p:?}");
            p.heading += (c.right - c.left) / wheel_base * 0.02;
        }
    }
}
