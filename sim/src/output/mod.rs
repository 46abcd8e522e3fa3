//! What a run writes: the trajectory log, the GIF, pictures and arrays.
pub mod draw;
pub mod fixed;
pub mod gif;
pub mod npy;
pub mod trajectory;

pub use gif::GifRecorder;
pub use trajectory::{TickRows, TrajectoryLog};

/// `name` made safe as part of a file name: ASCII letters, digits, `-` and the characters in `keep`
/// stay, every other character becomes `_`.
pub fn file_safe(name: &str, keep: &[char]) -> String {
    name.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || keep.contains(&c) {
                c
            } else {
                '_'
            }
        })
        .collect()
}
