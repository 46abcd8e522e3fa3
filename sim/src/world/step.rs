//! One step of a world, composed from the stages: decide -> drive -> physics -> track -> inject ->
//! sense, with the field step beside the robots' motion.
use super::stages::{decide_and_drive, drive, index, inject, physics, sense, step_fields, track};
use super::{PARALLEL_ROBOTS, World};
use crate::behaviour::WheelCommand;

impl World {
    /// One step with every robot's own behaviour deciding from its current observation.
    pub fn step(&mut self) {
        decide_and_drive(&mut self.robots, self.sensing.observations(), self.dt);
        self.advance();
    }

    /// One step with the given wheel commands (one per robot, m/s), e.g. from a learned policy.
    /// Non-finite commands are treated as a stop.
    ///
    /// # Panics
    /// If `commands.len()` differs from the number of robots (a programming error: the environment
    /// layers check the shape of user input before it gets here).
    pub fn step_with_commands(&mut self, commands: &[WheelCommand]) {
        assert_eq!(
            commands.len(),
            self.robots.len(),
            "one wheel command per robot"
        );
        drive(&mut self.robots, commands, self.dt);
        self.advance();
    }

    /// The rest of a step once every robot's drive has its command: motion, fields, injection, sensing.
    fn advance(&mut self) {
        let dt = self.dt;
        self.tick += 1;
        self.time = self.tick as f32 * dt;
        let time = self.time;
        // The fields evolve from the last step's deposits without the robots, and the robots move
        // without the fields: a large world runs the field pass (parallel, bound by memory bandwidth)
        // beside the contact solver, tracker and robot index (serial). Nothing either side reads what
        // the other writes, so the results are those of running them one after the other.
        let parallel = self.robots.len() >= PARALLEL_ROBOTS;
        let (robots, tracking, sensing) = (&mut self.robots, &mut self.tracking, &mut self.sensing);
        let mut move_robots = || {
            physics(robots, dt);
            track(tracking, time, robots.poses());
            index(sensing, robots.poses());
        };
        let fields = &mut self.fields;
        let mut step_fields = || step_fields(fields, dt, parallel);
        if parallel {
            rayon::join(move_robots, step_fields);
        } else {
            move_robots();
            step_fields();
        }
        inject(
            &mut self.injection,
            &mut self.fields,
            self.robots.physics.poses(),
            self.tracking.tracked(),
            dt,
        );
        self.sense();
    }

    /// Every robot's observation from the current screen and poses (after building or moving robots).
    pub(super) fn observe(&mut self) {
        index(&mut self.sensing, self.robots.physics.poses());
        self.sense();
    }

    /// Stage `sense` over this world's sets, at the poses last indexed.
    fn sense(&mut self) {
        sense(
            &mut self.sensing,
            &mut self.fields,
            &self.screen,
            self.robots.physics.poses(),
            &mut self.robots.slots,
            self.time,
        );
    }
}
