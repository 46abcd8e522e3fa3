//! What a loop function (an RL task's rewards, a metric) sees of an arena: the robots' poses as the
//! host knows them, their observations and drives, and the fields. A simulated [`World`] is one; so is
//! a rig's host, whose poses come from a real tracker.
use super::{FieldSet, RobotSlot, World};
use crate::behaviour::Observation;
use crate::field::Pheromone;
use crate::robot::{ColiasParams, Pose};
use crate::screen::ScreenSpec;
use glam::Vec2;

pub trait ArenaView {
    /// Arena size, m.
    fn arena(&self) -> Vec2;
    fn screen(&self) -> &ScreenSpec;
    fn robot_params(&self) -> &ColiasParams;
    /// Every robot's pose: the true one in a simulation, the tracked one on a rig.
    fn poses(&self) -> &[Pose];
    /// What each robot senses now.
    fn observations(&self) -> &[Observation];
    /// Per-robot group, drive state and last command.
    fn robots(&self) -> &[RobotSlot];
    /// The pheromone fields as the screen shows them.
    fn fields(&self) -> &FieldSet;
    fn pheromones(&self) -> &[Pheromone] {
        self.fields().pheromones()
    }
    /// Pheromone `index`'s value at `p` as of the current observations, and its gradient.
    fn pheromone_value_and_gradient_observed(
        &self,
        index: usize,
        p: Vec2,
        step: f32,
    ) -> (f32, Vec2) {
        self.fields().value_and_gradient_observed(index, p, step)
    }
    /// Role of robot `i` (its group's `role`).
    fn role(&self, i: usize) -> &str;
    fn robot_count(&self) -> usize {
        self.poses().len()
    }
    /// Robot `i`'s heading vector (`poses()[i].forward()`; a world returns the one its sensing
    /// computed, not a second `sin_cos`).
    fn forward(&self, i: usize) -> Vec2 {
        self.poses()[i].forward()
    }
    /// The arena's static obstacles (none unless the view has some).
    fn obstacles(&self) -> &crate::arena::Obstacles {
        static NONE: std::sync::LazyLock<crate::arena::Obstacles> =
            std::sync::LazyLock::new(Default::default);
        &NONE
    }
}

impl ArenaView for World {
    fn forward(&self, i: usize) -> Vec2 {
        World::forward(self, i)
    }
    fn obstacles(&self) -> &crate::arena::Obstacles {
        World::obstacles(self)
    }
    fn arena(&self) -> Vec2 {
        World::arena(self)
    }
    fn screen(&self) -> &ScreenSpec {
        World::screen(self)
    }
    fn robot_params(&self) -> &ColiasParams {
        World::robot_params(self)
    }
    fn poses(&self) -> &[Pose] {
        World::poses(self)
    }
    fn observations(&self) -> &[Observation] {
        World::observations(self)
    }
    fn robots(&self) -> &[RobotSlot] {
        World::robots(self)
    }
    fn fields(&self) -> &FieldSet {
        &self.fields
    }
    fn role(&self, i: usize) -> &str {
        World::role(self, i)
    }
    fn robot_count(&self) -> usize {
        World::robot_count(self)
    }
}
