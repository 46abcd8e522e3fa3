//! The robot set: bodies (rapier or discs), and per robot its group, behaviour, random stream, drive
//! state and last command. Stages `decide_and_drive`, `drive` and `physics`.
use super::PARALLEL_ROBOTS;
use super::Sensing;
use crate::behaviour::{Behaviour, Observation, WheelCommand};
use crate::rng::SimRng;
use crate::robot::{ArenaPhysics, ColiasParams, DriveState, Pose, RapierHost, lag_fraction};
use rayon::prelude::*;

/// Per-robot state that the world keeps apart from physics.
pub struct RobotSlot {
    /// Index of the scenario's robot group this robot comes from.
    pub group: usize,
    pub behaviour: Box<dyn Behaviour>,
    /// This robot's own random stream (sensor noise, behaviour choices).
    pub rng: SimRng,
    pub drive: DriveState,
    /// Command applied in the last step.
    pub command: WheelCommand,
    /// The robot's own wheels, motor and command latency (`[individual]`); `None`: the nominal
    /// `[robot]` model.
    pub actuation: Option<crate::robot::Actuation>,
}

pub struct RobotSet {
    pub(super) params: ColiasParams,
    pub(super) physics: ArenaPhysics,
    pub(super) slots: Vec<RobotSlot>,
    /// Scratch: each robot's body velocity (forward, yaw rate) from its drive, for physics.
    velocities: Vec<(f32, f32)>,
}

impl RobotSet {
    pub fn new(params: ColiasParams, physics: ArenaPhysics, slots: Vec<RobotSlot>) -> Self {
        RobotSet {
            params,
            physics,
            slots,
            velocities: Vec::new(),
        }
    }
    pub fn len(&self) -> usize {
        self.slots.len()
    }
    pub fn is_empty(&self) -> bool {
        self.slots.is_empty()
    }
    pub fn params(&self) -> &ColiasParams {
        &self.params
    }
    /// True poses.
    pub fn poses(&self) -> &[Pose] {
        self.physics.poses()
    }
    pub fn slots(&self) -> &[RobotSlot] {
        &self.slots
    }
    pub fn slots_mut(&mut self) -> &mut [RobotSlot] {
        &mut self.slots
    }
}

/// Robot `slot` takes wheel command `cmd` (a non-finite one is a stop): its drive's lag advances by
/// `dt` (`alpha`: the nominal lag's [`lag_fraction`] over `dt`), and the body velocity (forward, yaw
/// rate) it gives is returned.
fn drive_one(
    slot: &mut RobotSlot,
    cmd: WheelCommand,
    params: &ColiasParams,
    dt: f32,
    alpha: f32,
) -> (f32, f32) {
    let cmd = if cmd.left.is_finite() && cmd.right.is_finite() {
        cmd
    } else {
        WheelCommand::STOP
    };
    slot.command = cmd;
    match &mut slot.actuation {
        Some(own) => own.drive(&mut slot.drive, cmd, params, dt),
        None => slot.drive.approach(cmd, params, [1.0, 1.0], alpha),
    }
    slot.drive.body_velocity(params)
}

/// Stages `decide` and `drive` in one pass over the robots (one parallel region, not two): every
/// robot takes its override if it has one (an agent's command from a policy), or else its own
/// behaviour decides from its observation; its drive takes the command. `overrides` is one entry
/// per robot, or empty for none.
///
/// Reads `observations` and `overrides`; writes each deciding slot's behaviour state and random
/// stream, every slot's drive and command, and the body velocities that [`physics`] reads.
pub fn decide_and_drive(
    robots: &mut RobotSet,
    observations: &[Observation],
    overrides: &[Option<WheelCommand>],
    dt: f32,
) {
    let params = &robots.params;
    let alpha = lag_fraction(params.motor_lag, dt);
    let decide_and_drive = |(i, (slot, obs)): (usize, (&mut RobotSlot, &Observation))| {
        let cmd = match overrides.get(i) {
            Some(Some(cmd)) => *cmd,
            _ => slot.behaviour.act(obs, &mut slot.rng),
        };
        drive_one(slot, cmd, params, dt, alpha)
    };
    robots.velocities.clear();
    if robots.slots.len() >= PARALLEL_ROBOTS {
        robots
            .slots
            .par_iter_mut()
            .zip(observations.par_iter())
            .enumerate()
            .map(decide_and_drive)
            .collect_into_vec(&mut robots.velocities);
    } else {
        let velocities = robots
            .slots
            .iter_mut()
            .zip(observations.iter())
            .enumerate()
            .map(decide_and_drive);
        robots.velocities.extend(velocities);
    }
}

/// Stage `drive` with given wheel commands (one per robot, m/s; non-finite ones are a stop).
///
/// Reads `commands`; writes each slot's drive and command, and the body velocities that [`physics`]
/// reads.
pub fn drive(robots: &mut RobotSet, commands: &[WheelCommand], dt: f32) {
    let params = &robots.params;
    let alpha = lag_fraction(params.motor_lag, dt);
    let drive =
        |(slot, cmd): (&mut RobotSlot, &WheelCommand)| drive_one(slot, *cmd, params, dt, alpha);
    robots.velocities.clear();
    if robots.slots.len() >= PARALLEL_ROBOTS {
        robots
            .slots
            .par_iter_mut()
            .zip(commands)
            .map(drive)
            .collect_into_vec(&mut robots.velocities);
    } else {
        let velocities = robots.slots.iter_mut().zip(commands).map(drive);
        robots.velocities.extend(velocities);
    }
}

/// Stage `physics`: moves the bodies by `dt` at the velocities the last drive stage set (walls and
/// contacts included).
///
/// Reads the body velocities and the heading vectors sensing computed at the bodies' poses (see
/// [`Sensing::forward`]); writes the bodies (true poses).
pub fn physics(robots: &mut RobotSet, sensing: &Sensing, dt: f32) {
    let forward = |i: usize, heading: f32| sensing.forward(i, heading);
    robots.physics.step_facing(&robots.velocities, dt, forward);
}

/// Stage `physics` for a world whose rapier steps run in `host`: the arena's own part (see
/// [`crate::robot::RapierHost`]); [`finish_physics_in`] completes it after the host's step.
pub fn physics_in(robots: &mut RobotSet, dt: f32, host: &mut RapierHost) {
    robots.physics.step_in(host, &robots.velocities, dt);
}

/// The end of stage [`physics_in`], after the host's step: the poses of robots that went through it.
pub fn finish_physics_in(robots: &mut RobotSet, host: &mut RapierHost) {
    robots.physics.finish_in(host);
}

/// Stage `decide` alone, for a host whose robots drive themselves (the rig): every robot's behaviour
/// decides from its observation; the command (a stop if not finite) goes to `commands` and is kept as
/// the slot's last command, which the next observation reports.
///
/// Reads `observations`; writes each slot's behaviour state, random stream and command, and `commands`.
pub fn decide(
    slots: &mut [RobotSlot],
    observations: &[Observation],
    commands: &mut [WheelCommand],
) {
    for ((slot, obs), out) in slots.iter_mut().zip(observations).zip(commands) {
        let cmd = slot.behaviour.act(obs, &mut slot.rng);
        let cmd = if cmd.left.is_finite() && cmd.right.is_finite() {
            cmd
        } else {
            WheelCommand::STOP
        };
        slot.command = cmd;
        *out = cmd;
    }
}
