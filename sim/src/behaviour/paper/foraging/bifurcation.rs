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

/// The front sensor is in the wedge between two branches below this fraction of the threshold: at the
/// outer edge of a sharp bend it only grazes the trail, reading a little above that.
const WEDGE_FRONT: f32 = 0.5;

/// The bifurcation seen by the sensors, if any (see the module documentation).
pub fn detect_bifurcation(obs: &Observation, threshold: f32) -> Option<BifurcationKind> {
    use TrailClass::*;
    let class = |n: usize| TrailClass::of(obs.intensity[n], threshold);
    let (l, r, f) = (class(SENSOR_LEFT), class(SENSOR_RIGHT), class(SENSOR_FRONT));
    if l == Off || r == Off {
        return None;
    }
    // The wedge between two branches, or cyan on one side only. Blue on one side and magenta on the
    // other with the front on the trail is the start of an SRP piece seen at an angle, one trail.
    let wedge = obs.intensity[SENSOR_FRONT][BLUE] < WEDGE_FRONT * threshold;
    let cyan_split = (l == Cyan) != (r == Cyan);
    if !wedge && !cyan_split {
        return None;
    }
    // The SRP piece begins a few centimetres into its branch, where the front sensor may see it
    // before the side sensor over that branch does.
    Some(if l == Magenta || r == Magenta || f == Magenta {
        BifurcationKind::Magenta
    } else if cyan_split {
        BifurcationKind::CyanBlue
    } else {
        BifurcationKind::Plain
    })
}
