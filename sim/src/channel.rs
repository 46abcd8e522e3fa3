//! Colour channels, one type wherever a scenario names one: [`Channel`], a colour of the screen (the
//! pheromone drawn in red, green or blue: what a behaviour follows or a task watches), and
//! [`ImageChannel`], what is read from a map's or a mask's PNG (a colour, alpha, or luma).
//! Both are written in scenarios as lower-case strings (`"r"`, `"luma"`) and refused with the values
//! they may take.
use serde::{Deserialize, Serialize};
use std::fmt;

/// A colour channel of the screen.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(try_from = "String", into = "String")]
pub enum Channel {
    R,
    G,
    B,
}

impl Channel {
    /// Index into an RGB triple.
    pub fn index(self) -> usize {
        self as usize
    }

    /// `"r"`, `"g"` or `"b"` (also `"red"`, `"green"`, `"blue"`).
    pub fn parse(name: &str) -> Option<Channel> {
        match name {
            "r" | "red" => Some(Channel::R),
            "g" | "green" => Some(Channel::G),
            "b" | "blue" => Some(Channel::B),
            _ => None,
        }
    }

    pub fn name(self) -> &'static str {
        ["r", "g", "b"][self.index()]
    }
}

impl TryFrom<String> for Channel {
    type Error = String;
    fn try_from(s: String) -> Result<Self, String> {
        Channel::parse(&s).ok_or_else(|| format!("{s:?} is not \"r\", \"g\" or \"b\""))
    }
}

impl From<Channel> for String {
    fn from(c: Channel) -> String {
        c.name().to_string()
    }
}

impl fmt::Display for Channel {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A channel of an RGBA image read as a map or a mask.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(try_from = "String", into = "String")]
pub enum ImageChannel {
    R,
    G,
    B,
    A,
    /// ITU-R 601 luma of the colour (alpha ignored).
    Luma,
}

impl ImageChannel {
    pub const NAMES: [&'static str; 5] = ["r", "g", "b", "a", "luma"];

    pub fn parse(name: &str) -> Option<ImageChannel> {
        use ImageChannel::*;
        [R, G, B, A, Luma].into_iter().find(|c| c.name() == name)
    }

    pub fn name(self) -> &'static str {
        Self::NAMES[self as usize]
    }

    /// The channel's level of pixel `p`.
    pub fn pick(self, p: &[u8; 4]) -> u8 {
        match self {
            ImageChannel::R => p[0],
            ImageChannel::G => p[1],
            ImageChannel::B => p[2],
            ImageChannel::A => p[3],
            ImageChannel::Luma => {
                ((299 * p[0] as u32 + 587 * p[1] as u32 + 114 * p[2] as u32) / 1000).min(255) as u8
            }
        }
    }
}

impl TryFrom<String> for ImageChannel {
    type Error = String;
    fn try_from(s: String) -> Result<Self, String> {
        ImageChannel::parse(&s)
            .ok_or_else(|| format!("{s:?} is not \"r\", \"g\", \"b\", \"a\" or \"luma\""))
    }
}

impl From<ImageChannel> for String {
    fn from(c: ImageChannel) -> String {
        c.name().to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_bad_ones_are_refused_with_the_choices() {
        for c in [Channel::R, Channel::G, Channel::B] {
            assert_eq!(Channel::parse(c.name()), Some(c));
        }
        assert_eq!(Channel::parse("green"), Some(Channel::G));
        let e = Channel::try_from("x".to_string()).unwrap_err();
        assert!(e.contains("\"r\", \"g\" or \"b\""), "{e}");
        for name in ImageChannel::NAMES {
            assert_eq!(ImageChannel::parse(name).unwrap().name(), name);
        }
        assert!(ImageChannel::try_from("luminance".to_string()).is_err());
        assert_eq!(ImageChannel::Luma.pick(&[255, 255, 255, 0]), 255);
        assert_eq!(ImageChannel::A.pick(&[1, 2, 3, 4]), 4);
    }
}
