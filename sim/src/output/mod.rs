//! What a run writes: the trajectory log, the GIF, pictures and arrays.
pub mod draw;
pub mod fixed;
pub mod gif;
pub mod npy;
pub mod trajectory;

pub use gif::GifRecorder;
pub use trajectory::{TickRows, TrajectoryLog};
