//! A world: one arena as data sets (fields, robots, tracking, injection rules, sensing) and the stage
//! functions that step them. [`World::step`] composes every stage in the order of one 20 ms step:
//!
//! ```text
//! decide ─> drive ─> physics ─> track ─┐
//!                                      ├─> inject ─> sense ─> observations
//!                         step_fields ─┘
//! ```
//!
//! The stages are public ([`stages`]) so that a host with a real arena can compose `inject`,
//! `step_fields` and `sense` with poses from a real tracker.

mod access;
mod build;
mod fields;
mod inject;
mod place;
mod robots;
mod sensing;
mod step;
mod tracking;
mod view;

pub use build::WorldParts;
pub use fields::FieldSet;
pub use inject::{Injection, TrailSegment};
pub use robots::{RobotSet, RobotSlot};
pub use sensing::{RobotSensors, Sensing};
pub use tracking::Tracking;
pub use view::ArenaView;

/// The stage functions of a step. Each takes the data sets it touches by reference and documents what
/// it reads and writes; none keeps state of its own beyond scratch buffers inside the sets.
pub mod stages {
    pub use super::fields::step_fields;
    pub use super::inject::inject;
    pub use super::robots::{
        decide, decide_and_drive, drive, finish_physics_in, physics, physics_in,
    };
    pub use super::sensing::{index, sense};
    pub use super::tracking::track;
}

use crate::scenario::Scenario;
use crate::screen::ScreenSpec;
use glam::Vec2;

/// Below this many robots a world steps its robots on one thread: rayon's overhead would dominate, and
/// batched environments parallelise over worlds instead.
pub(crate) const PARALLEL_ROBOTS: usize = 64;

pub struct World {
    scenario: Scenario,
    time: f32,
    tick: u64,
    dt: f32,
    arena: Vec2,
    screen: ScreenSpec,
    fields: FieldSet,
    robots: RobotSet,
    tracking: Tracking,
    injection: Injection,
    sensing: Sensing,
}
