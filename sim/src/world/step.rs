//! One step of a world: behaviours -> drive -> physics -> tracker -> fields and injection -> sensors.
//! In a large world the field pass runs beside physics, tracker and robot index (they share no data).
use super::World;
use crate::behaviour::{Observation, WheelCommand};
use crate::field::{FieldBackend, GridPrefetcher, Pheromone};
use crate::robot::ColiasParams;
use crate::sensors::SENSOR_RADIUS;
use crate::sensors::sensor_positions;
use rayon::prelude::*;

/// Below this many robots a world steps its robots on one thread: rayon's overhead would dominate, and
/// batched environments parallelise over worlds instead. (At 100 robots one thread and two were even in
/// session 7: 0.33 ms a step either way, alternated 6 times; on session 8's faster host two threads
/// paid: 0.13 against 0.29 ms, `RAYON_NUM_THREADS=1|2 profile_swarm "bench: 100"` alternated 3 times.)
const PARALLEL_ROBOTS: usize = 64;

/// Robot `slot` takes wheel command `cmd` (a non-finite one is a stop): its drive's lag advances by
/// `dt`, and the body velocity (forward, yaw rate) it gives is returned.
fn drive(
    slot: &mut super::RobotSlot,
    cmd: WheelCommand,
    params: &ColiasParams,
    dt: f32,
) -> (f32, f32) {
    let cmd = if cmd.left.is_finite() && cmd.right.is_finite() {
        cmd
    } else {
        WheelCommand::STOP
    };
    slot.command = cmd;
    slot.drive.update(cmd, params, dt);
    slot.drive.body_velocity(params)
}

/// Advances every field by `dt`: on `backend` when there is one, else each field's own pass, the fields
/// side by side when `parallel` (each large field's pass also splits into bands itself).
fn step_fields(
    pheromones: &mut [Pheromone],
    backend: &mut Option<Box<dyn FieldBackend>>,
    dt: f32,
    parallel: bool,
) {
    match backend.as_mut() {
        Some(backend) => backend.step(pheromones, dt),
        None if parallel => pheromones.par_iter_mut().for_each(|p| p.step(dt)),
        None => pheromones.iter_mut().for_each(|p| p.step(dt)),
    }
}

impl World {
    /// One step with every robot's own behaviour deciding from its current observation.
    pub fn step(&mut self) {
        let (dt, params) = (self.dt, &self.robot_params);
        // Deciding and driving in one pass over the robots (one parallel region, not two).
        let decide_and_drive = |(slot, obs): (&mut super::RobotSlot, &Observation)| {
            let cmd = slot.behaviour.act(obs, &mut slot.rng);
            drive(slot, cmd, params, dt)
        };
        self.velocities.clear();
        if self.robots.len() >= PARALLEL_ROBOTS {
            self.robots
                .par_iter_mut()
                .zip(self.observations.par_iter())
                .map(decide_and_drive)
                .collect_into_vec(&mut self.velocities);
        } else {
            let velocities = self
                .robots
                .iter_mut()
                .zip(self.observations.iter())
                .map(decide_and_drive);
            self.velocities.extend(velocities);
        }
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
        let (dt, params) = (self.dt, &self.robot_params);
        let drive =
            |(slot, cmd): (&mut super::RobotSlot, &WheelCommand)| drive(slot, *cmd, params, dt);
        self.velocities.clear();
        if self.robots.len() >= PARALLEL_ROBOTS {
            self.robots
                .par_iter_mut()
                .zip(commands)
                .map(drive)
                .collect_into_vec(&mut self.velocities);
        } else {
            let velocities = self.robots.iter_mut().zip(commands).map(drive);
            self.velocities.extend(velocities);
        }
        self.advance();
    }

    /// The rest of a step once every robot's drive has its command: motion, fields, injection, sensing.
    fn advance(&mut self) {
        let dt = self.dt;
        self.tick += 1;
        self.time = self.tick as f32 * dt;
        // The fields evolve from the last step's deposits without the robots, and the robots move
        // without the fields: a large world runs the field pass (parallel, bound by memory bandwidth)
        // beside the contact solver, tracker and robot index (serial). Nothing either side reads what
        // the other writes, so the results are those of running them one after the other.
        let mut pheromones = std::mem::take(&mut self.pheromones);
        let mut backend = self.field_backend.take();
        let parallel = self.robots.len() >= PARALLEL_ROBOTS;
        let mut step_fields = || step_fields(&mut pheromones, &mut backend, dt, parallel);
        if parallel {
            rayon::join(|| self.move_robots(), step_fields);
        } else {
            self.move_robots();
            step_fields();
        }
        self.pheromones = pheromones;
        self.field_backend = backend;
        self.inject();
        self.sense();
    }

    /// Physics, the tracker's view of the new poses, and the robot index that sensing reads.
    fn move_robots(&mut self) {
        self.physics.step(&self.velocities, self.dt);
        let tracked = self
            .tracker
            .update(self.time, self.physics.poses(), &mut self.tracker_rng);
        self.tracked.copy_from_slice(tracked);
        self.index_robots();
    }

    /// Recomputes every robot's observation from the current screen and poses.
    pub(super) fn observe(&mut self) {
        self.index_robots();
        self.sense();
    }

    /// The neighbour index of the bumpers and the sensor positions, from the current poses.
    fn index_robots(&mut self) {
        let poses = self.physics.poses();
        let cell = 2.0 * self.robot_params.radius + self.bumper_params.range;
        self.positions.clear();
        self.positions.extend(poses.iter().map(|p| p.pos));
        self.neighbours.rebuild(self.arena, cell, &self.positions);
        // Sensor positions once per robot: sensing reads robot i's, prefetching robot i + 1's.
        self.sensor_points.clear();
        self.sensor_points
            .extend(poses.iter().map(|p| sensor_positions(p, SENSOR_RADIUS)));
    }

    /// Every robot's observation from the current screen, robot index and poses.
    fn sense(&mut self) {
        let poses = self.physics.poses();
        self.frozen.refresh(&self.pheromones);
        let sensor_points = &self.sensor_points;
        let (pheromones, frozen, screen, sensor, neighbours) = (
            &self.pheromones,
            &self.frozen,
            &self.screen,
            &self.sensor,
            &self.neighbours,
        );
        let (radius, arena, bumper, time) = (
            self.robot_params.radius,
            self.arena,
            &self.bumper_rays,
            self.time,
        );
        let prefetcher = GridPrefetcher::new(pheromones);
        let sense = |(i, (slot, obs)): (usize, (&mut super::RobotSlot, &mut Observation))| {
            // The grid cells under the next robot's sensors are scattered over large fields: ask for
            // them now so that their cache misses overlap with this robot's work.
            if let (Some(prefetcher), Some(next)) = (&prefetcher, sensor_points.get(i + 1)) {
                prefetcher.prefetch(next);
            }
            let mut o = Observation {
                time,
                last_command: slot.command,
                ..Observation::default()
            };
            o.counts =
                sensor.read_all(pheromones, frozen, screen, &sensor_points[i], &mut slot.rng);
            o.intensity = sensor.intensities(&o.counts);
            o.bumpers = neighbours.bumpers(i, poses, radius, arena, bumper);
            *obs = o;
        };
        if self.robots.len() >= PARALLEL_ROBOTS {
            self.robots
                .par_iter_mut()
                .zip(self.observations.par_iter_mut())
                .enumerate()
                .for_each(sense);
        } else {
            self.robots
                .iter_mut()
                .zip(self.observations.iter_mut())
                .enumerate()
                .for_each(sense);
        }
    }
}
