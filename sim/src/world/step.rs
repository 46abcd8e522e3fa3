//! One step of a world, composed from the stages: decide -> drive -> physics -> track -> inject ->
//! sense, with the field step beside the robots' motion.
use super::stages::{
    decide_and_drive, drive, finish_physics_in, index, inject, physics, physics_in, step_fields,
    track,
};
use super::{PARALLEL_ROBOTS, World};
use crate::behaviour::WheelCommand;
use crate::robot::RapierHost;

impl World {
    /// One step with every robot's own behaviour deciding from its current observation.
    pub fn step(&mut self) {
        self.step_with_overrides(&[]);
    }

    /// One step with one controller per robot: a robot with an override takes it (an agent's
    /// command from a policy), the others decide with their own behaviour, as in [`Self::step`].
    /// `overrides` is one entry per robot, or empty for none; non-finite commands are a stop.
    ///
    /// # Panics
    /// If `overrides` is neither empty nor one per robot (a programming error).
    pub fn step_with_overrides(&mut self, overrides: &[Option<WheelCommand>]) {
        self.decide(overrides);
        self.advance();
    }

    fn decide(&mut self, overrides: &[Option<WheelCommand>]) {
        assert!(
            overrides.is_empty() || overrides.len() == self.robots.len(),
            "one override (or none) per robot"
        );
        let observations = self.sensing.observations();
        decide_and_drive(&mut self.robots, observations, overrides, self.dt);
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

    /// Moves this world's rapier bodies into slot `slot` of `host`, which then takes its contact
    /// steps together with the other worlds there (see [`RapierHost`]): a batch of small worlds
    /// steps several times faster so. Returns false, and changes nothing, where the world does not
    /// fit the host (the disc solver, another arena size, no such slot).
    pub fn attach_physics(&mut self, host: &mut RapierHost, slot: usize) -> bool {
        self.robots.physics.attach(host, slot)
    }

    /// The first half of [`Self::step_with_overrides`] for a world attached to `host`: the
    /// decisions and the world's own part of the motion. Once every world of the host began its
    /// step, call [`RapierHost::step`], then [`Self::finish_step_in`] on each. A world not attached
    /// to `host` moves alone here.
    ///
    /// # Panics
    /// If `overrides` is neither empty nor one per robot.
    pub fn begin_step_in(&mut self, overrides: &[Option<WheelCommand>], host: &mut RapierHost) {
        self.decide(overrides);
        self.advance_clock();
        physics_in(&mut self.robots, self.dt, host);
    }

    /// The second half of a step begun with [`Self::begin_step_in`], after [`RapierHost::step`]:
    /// the poses, then tracking, fields, injection and sensing as in any step.
    pub fn finish_step_in(&mut self, host: &mut RapierHost) {
        finish_physics_in(&mut self.robots, host);
        let (dt, time) = (self.dt, self.time);
        track(&mut self.tracking, time, self.robots.poses());
        index(&mut self.sensing, self.robots.poses());
        step_fields(&mut self.fields, dt, self.robots.len() >= PARALLEL_ROBOTS);
        self.inject_and_sense();
    }

    fn advance_clock(&mut self) {
        self.tick += 1;
        self.time = self.tick as f32 * self.dt;
    }

    /// The rest of a step once every robot's drive has its command: motion, fields, injection, sensing.
    fn advance(&mut self) {
        let dt = self.dt;
        self.advance_clock();
        let time = self.time;
        // The fields evolve from the last step's deposits without the robots, and the robots move
        // without the fields: a large world runs the field pass (parallel, bound by memory bandwidth)
        // beside the contact solver, tracker and robot index (serial). Nothing either side reads what
        // the other writes, so the results are those of running them one after the other.
        let parallel = self.robots.len() >= PARALLEL_ROBOTS;
        let (robots, tracking, sensing) = (&mut self.robots, &mut self.tracking, &mut self.sensing);
        let mut move_robots = || {
            physics(robots, sensing, dt);
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
        self.inject_and_sense();
    }

    /// Stages `inject` and `sense`, the end of every step.
    fn inject_and_sense(&mut self) {
        let dt = self.dt;
        inject(
            &mut self.injection,
            &mut self.fields,
            self.robots.physics.poses(),
            self.tracking.tracked(),
            dt,
        );
        if !self.fields.external_grids() {
            self.sense();
        }
    }

    /// Ends a step of a world whose grid pheromones live outside it
    /// ([`crate::world::FieldSet::set_external_grids`]): every robot's observation from the colour
    /// sensors' footprint level sums `sums` (four per robot, over [`World::footprint_offsets`] from
    /// [`World::sensor_centres`]), as
    /// [`World::step`] would sense them on a screen with those sums.
    ///
    /// # Panics
    /// If `sums` does not hold four entries per robot.
    pub fn sense_from_sums(&mut self, sums: &[[u32; 3]]) {
        self.sense_with(Some(sums));
    }

    /// Every robot's observation from the current screen and poses (after building or moving robots).
    pub(super) fn observe(&mut self) {
        index(&mut self.sensing, self.robots.physics.poses());
        self.sense();
    }

    /// Stage `sense` over this world's sets, at the poses last indexed.
    fn sense(&mut self) {
        self.sense_with(None);
    }

    /// Stage `sense`, from the footprint level sums `sums` when given.
    fn sense_with(&mut self, sums: Option<&[[u32; 3]]>) {
        let sets = super::sensing::SenseSets {
            fields: &mut self.fields,
            screen: &self.screen,
            poses: self.robots.physics.poses(),
            slots: &mut self.robots.slots,
            time: self.time,
        };
        super::sensing::sense_with(&mut self.sensing, sets, sums);
    }
}
