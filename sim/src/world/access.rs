//! What a world shows of itself: clocks, parameters, poses, observations and field values.
use super::{FieldSet, RobotSet, RobotSlot, Sensing, Tracking, World};
use crate::behaviour::Observation;
use crate::field::{FieldBackend, Pheromone};
use crate::robot::{ColiasParams, Pose};
use crate::scenario::Scenario;
use crate::screen::ScreenSpec;
use crate::sensors::{ColourSensor, NeighbourIndex};
use crate::tracker::TrackedPose;
use glam::Vec2;

impl World {
    /// Simulation time, s.
    pub fn time(&self) -> f32 {
        self.time
    }
    /// Number of steps taken.
    pub fn tick(&self) -> u64 {
        self.tick
    }
    pub fn dt(&self) -> f32 {
        self.dt
    }
    pub fn scenario(&self) -> &Scenario {
        &self.scenario
    }
    /// Arena size, m.
    pub fn arena(&self) -> Vec2 {
        self.arena
    }
    pub fn screen(&self) -> &ScreenSpec {
        &self.screen
    }
    pub fn pheromones(&self) -> &[Pheromone] {
        self.fields.pheromones()
    }
    pub fn pheromones_mut(&mut self) -> &mut [Pheromone] {
        self.fields.pheromones_mut()
    }
    pub fn robot_count(&self) -> usize {
        self.robots.len()
    }
    pub fn robots(&self) -> &[RobotSlot] {
        &self.robots.slots
    }
    pub fn robot_params(&self) -> &ColiasParams {
        &self.robots.params
    }
    /// True poses.
    pub fn poses(&self) -> &[Pose] {
        self.robots.poses()
    }
    /// Robot `i`'s heading vector, [`Pose::forward`] of its pose: the one sensing computed at it.
    ///
    /// # Panics
    /// If there is no robot `i`.
    pub fn forward(&self, i: usize) -> glam::Vec2 {
        self.sensing.forward(i, self.poses()[i].heading)
    }
    /// The arena's static obstacles (empty when the scenario has none).
    pub fn obstacles(&self) -> &crate::arena::Obstacles {
        self.sensing.obstacles()
    }
    /// Poses as the tracker last delivered them.
    pub fn tracked(&self) -> &[TrackedPose] {
        self.tracking.tracked()
    }
    /// Capture time of the tracker's newest delivered frame, s: a tracked pose stamped earlier is a
    /// robot that dropped out of that frame.
    pub fn tracked_frame_stamp(&self) -> Option<f32> {
        self.tracking.latest_frame_stamp()
    }
    /// What each robot senses now.
    pub fn observations(&self) -> &[Observation] {
        self.sensing.observations()
    }
    /// Role of robot `i` (its group's `role`).
    pub fn role(&self, i: usize) -> &str {
        &self.scenario.spec.robots[self.robots.slots[i].group].role
    }
    /// Pheromone `index`'s value at `p` as of the current observations (see
    /// [`FieldSet::value_observed`]).
    pub fn pheromone_value_observed(&self, index: usize, p: Vec2) -> f32 {
        self.fields.value_observed(index, p)
    }
    /// [`World::pheromone_value_observed`] and its gradient at `p` (see
    /// [`FieldSet::value_and_gradient_observed`]).
    pub fn pheromone_value_and_gradient_observed(
        &self,
        index: usize,
        p: Vec2,
        step: f32,
    ) -> (f32, Vec2) {
        self.fields.value_and_gradient_observed(index, p, step)
    }
    /// The colour sensor model shared by all robots.
    pub fn sensor(&self) -> &ColourSensor {
        self.sensing.sensor()
    }
    /// Robot `i`'s own four sensors with `[sensor] per_robot` (`None` without: every robot reads
    /// through [`World::sensor`]).
    pub fn robot_sensors(&self, i: usize) -> Option<&super::RobotSensors> {
        self.sensing.robot_sensors(i)
    }
    /// Robot `i`'s own colour gain and offset on its counts (`[individual]`; `None`: nominal).
    pub fn sensor_gain(&self, i: usize) -> Option<(f32, f32)> {
        self.sensing.sensor_gain(i)
    }
    /// Robot `i`'s own actuation (`[individual]`; `None`: the nominal `[robot]` model).
    pub fn actuation(&self, i: usize) -> Option<&crate::robot::Actuation> {
        self.robots
            .slots()
            .get(i)
            .and_then(|s| s.actuation.as_ref())
    }
    /// The neighbour index of the current poses (tests probe bumpers through it).
    pub fn neighbour_index(&self) -> &NeighbourIndex {
        self.sensing.neighbours()
    }
    /// Where the host believes robot `i` is, or `None` if the tracker has not seen it yet.
    pub fn injection_point(&self, i: usize) -> Option<Vec2> {
        self.injection
            .point(self.robots.poses(), self.tracking.tracked(), i)
    }
    /// Robot `i`'s deposit actions (`[[robots]] deposit_actions`), as fractions of their
    /// `max_rate` laid from the next step on; empty for a robot without any.
    pub fn deposit_actions(&self, i: usize) -> &[f32] {
        self.injection.deposit_actions(i)
    }
    /// Chooses how much robot `i` lays of each of its deposit actions from the next step on:
    /// fractions of `max_rate`, clamped to `[0, 1]` (0 lays nothing).
    pub fn set_deposit_actions(&mut self, i: usize, fractions: impl IntoIterator<Item = f32>) {
        self.injection.set_deposit_actions(i, fractions);
    }
    /// Installs a field backend that steps the pheromones from now on (`None`: the CPU).
    pub fn set_field_backend(&mut self, backend: Option<Box<dyn FieldBackend>>) {
        self.fields.set_backend(backend);
    }
    /// Hands the grid pheromones to an owner outside the world, or takes them back (see
    /// [`super::FieldSet::set_external_grids`]; a step then ends with [`World::sense_from_sums`]).
    pub fn set_external_grids(&mut self, external: bool) {
        self.fields.set_external_grids(external);
    }
    /// Whether the grid pheromones live outside the world.
    pub fn external_grids(&self) -> bool {
        self.fields.external_grids()
    }
    /// The trail segments of the last step, in scenario order.
    pub fn trail_segments(&self) -> &[super::TrailSegment] {
        self.injection.segments()
    }
    /// Robot `i`'s four colour sensors' centres at the current poses.
    pub fn sensor_centres(&self, i: usize) -> [Vec2; 4] {
        self.sensing.sensor_centres(i)
    }
    /// Where robot `i`'s colour sensors sample the screen, from a sensor's centre (see
    /// [`super::Sensing::footprint_offsets`]).
    pub fn footprint_offsets(&self, i: usize) -> [Vec2; crate::sensors::RING_POINTS + 1] {
        self.sensing.footprint_offsets(i)
    }
    /// The installed field backend's description, or `None` for the CPU.
    pub fn field_backend(&self) -> Option<String> {
        self.fields.backend_description()
    }
    /// Replaces the behaviour of robot `i` (e.g. with a learned policy); its colour is read from now
    /// on, whatever [`World::skip_unread_colour`] said.
    pub fn set_behaviour(&mut self, i: usize, behaviour: Box<dyn crate::behaviour::Behaviour>) {
        self.robots.slots[i].behaviour = behaviour;
        self.sensing.keep_colour_read(i);
    }
    /// Stops evaluating the colour sensors of robots that are not in `observers` and whose behaviour
    /// does not read colour ([`crate::behaviour::Behaviour::reads_colour`]): for a caller that reads
    /// no other robot's colour (an RL environment whose observers are its agents). Their readings are
    /// then 0, and everything else, every random stream included, stays as it was.
    pub fn skip_unread_colour(&mut self, observers: &[usize]) {
        let unread = (self.robots.slots.iter().enumerate())
            .map(|(i, slot)| !observers.contains(&i) && !slot.behaviour.reads_colour())
            .collect();
        self.sensing.set_colour_unread(unread);
    }
    /// Steps until the scenario's duration is reached.
    pub fn is_finished(&self) -> bool {
        self.tick >= self.scenario.steps()
    }

    /// The data sets, for hosts that run stages on their own.
    pub fn sets(&self) -> (&FieldSet, &RobotSet, &Tracking, &Sensing) {
        (&self.fields, &self.robots, &self.tracking, &self.sensing)
    }
}
