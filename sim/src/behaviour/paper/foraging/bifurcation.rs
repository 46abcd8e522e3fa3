//! What the colour sensors see of the trails, and the bifurcation seen by them (see the parent module's
//! documentation for the definition).
use super::super::{BLUE, GREEN, RED, SENSOR_FRONT, SENSOR_LEFT, SENSOR_RIGHT};
use crate::behaviour::Observation;

/// What one colour sensor sees of the trails.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TrailClass {
    /// No LAP.
    Off,
    /// LAP only.
    Blue,
    /// LAP and SAP.
    Cyan,
    /// LAP and SRP.
    Magenta,
}

impl TrailClass {
    /// Class of one sensor's `[r, g, b]` intensities.
    pub fn of(rgb: [f32; 3], threshold: f32) -> Self {
        if rgb[BLUE].is_nan() || rgb[BLUE] <= threshold {
            TrailClass::Off
        } else if rgb[RED] > threshold {
            TrailClass::Magenta
        } else if rgb[GREEN] > threshold {
            TrailClass::Cyan
        } else {
            TrailClass::Blue
        }
    }
}

/// Which trail the robot steers on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Trail {
    /// The LAP (blue channel).
    Lap,
    /// The cyan trail, LAP + SAP (green channel).
    Cyan,
    /// Blue but not cyan (`blue - green`): the blue branch of a cyan/blue bifurcation.
    BlueOnly,
}

impl Trail {
    /// The steering signal of eq. (7) for this trail at one sensor.
    pub fn signal(self, rgb: [f32; 3]) -> f32 {
        match self {
            Trail::Lap => rgb[BLUE],
            Trail::Cyan => rgb[GREEN],
            Trail::BlueOnly => rgb[BLUE] - rgb[GREEN],
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Side {
    Left,
    Right,
}

impl Side {
    /// +1 for left (counter-clockwise), -1 for right.
    pub fn sign(self) -> f32 {
        match self {
            Side::Left => 1.0,
            Side::Right => -1.0,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BifurcationKind {
    /// One side magenta (LAP + SRP): take the cyan side.
    Magenta,
    /// Cyan on one side, blue on the other: cyan with probability `cyan_probability`.
    CyanBlue,
    /// Both sides alike: a fair coin.
    Plain,
}

/// The bifurcation seen by the sensors, if any (see the module documentation).
pub fn detect_bifurcation(obs: &Observation, threshold: f32) -> Option<BifurcationKind> {
    let class = |n: usize| TrailClass::of(obs.intensity[n], threshold);
    let (l, r, f) = (class(SENSOR_LEFT), class(SENSOR_RIGHT), class(SENSOR_FRONT));
    if l == TrailClass::Off || r == TrailClass::Off {
        return None;
    }
    if f != TrailClass::Off && l == r {
        return None;
    }
    use TrailClass::*;
    Some(match (l, r) {
        (Magenta, _) | (_, Magenta) => BifurcationKind::Magenta,
        (Cyan, Blue) | (Blue, Cyan) => BifurcationKind::CyanBlue,
        _ => BifurcationKind::Plain,
    })
}
