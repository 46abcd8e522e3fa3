//! A robot's senses in the simulator: four downward colour sensors reading the screen, three IR bumpers.

mod bumper;
mod calibration;
mod colour;
mod frame;
mod layout;
mod pow_unit;

/// The spatial index the bumpers query (it lives in [`crate::spatial`]).
pub use crate::spatial::NeighbourIndex;
pub use bumper::{BumperParams, BumperRays, ray_disc, ray_walls, reading_for_distance};
pub use calibration::{ColourCalibration, RobotColour, SensorFit};
pub use colour::{
    ColourSensor, ColourSensorParams, RING_FRACTION, RING_POINTS, ScreenView, invert3,
};
pub use frame::frame_pixel;
pub use layout::{SENSOR_RADIUS, sensor_positions, sensor_positions_facing};
pub use pow_unit::pow_unit;
