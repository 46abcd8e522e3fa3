//! A robot's senses in the simulator: four downward colour sensors reading the screen, three IR bumpers.

mod bumper;
mod colour;
mod layout;

pub use bumper::{BumperParams, NeighbourIndex};
pub use colour::{ColourSensor, ColourSensorParams};
pub use layout::{sensor_positions, SENSOR_RADIUS};
