//! The `[[obstacles]]` keys of a scenario file, as plain serde structs (checked in [`super::shapes`]).
use serde::{Deserialize, Serialize};

/// The geometry of one obstacle.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ObstacleShape {
    /// A rectangle: `centre`, `size` (width, height), `angle` (degrees, counter-clockwise).
    Box,
    /// A disc: `centre`, `radius`.
    Disc,
    /// A closed polygon, convex or concave: `points` (at least 3, in order, not self-crossing).
    Polygon,
    /// A line wall: the polyline `points` (at least 2) with a `thickness` (round ends).
    Wall,
    /// The pixels of a PNG `image` stretched over the arena whose `channel` is at least
    /// `threshold` (0-255): each run of solid pixels becomes a box.
    Mask,
}

/// What the obstacle is on the real rig.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ObstacleKind {
    /// A real object standing on the screen: robots collide with it and their IR bumpers see it. The
    /// LCD does not draw it (it lies under the object); views of the arena draw its outline.
    #[default]
    Physical,
    /// Drawn on the LCD in `colour` (on top of the pheromones): the robots' colour sensors see it;
    /// robots drive over it and their bumpers do not.
    Printed,
}

/// One `[[obstacles]]` entry. Which keys are needed depends on `shape`; the others must be absent.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObstacleSpec {
    pub shape: ObstacleShape,
    #[serde(default)]
    pub kind: ObstacleKind,
    /// Screen levels r, g, b (0-255) a printed obstacle is drawn in (default black).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub colour: Option<[u8; 3]>,
    /// Centre, m (`box`, `disc`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub centre: Option<[f32; 2]>,
    /// Width and height, m (`box`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub size: Option<[f32; 2]>,
    /// Rotation, degrees counter-clockwise (`box`; default 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub angle: Option<f32>,
    /// Radius, m (`disc`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub radius: Option<f32>,
    /// Vertices, m (`polygon`, `wall`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub points: Option<Vec<[f32; 2]>>,
    /// Wall thickness, m (`wall`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub thickness: Option<f32>,
    /// PNG path, relative to the scenario file (`mask`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub image: Option<String>,
    /// Channel read from the image: "r", "g", "b", "a" or "luma" (`mask`; default "luma").
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub channel: Option<crate::channel::ImageChannel>,
    /// Level (0-255) from which a pixel is solid (`mask`; default 128).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub threshold: Option<u8>,
    /// Size in pixels the image must have, [width, height] (`mask`; optional check).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pixels: Option<[u32; 2]>,
}

/// `[arena] shape`: an arena bounded by a disc or a polygon inside the `[0, w] x [0, h]` rectangle
/// (by default the rectangle itself). The boundary is a wall robots collide with and bumpers see.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum ArenaShape {
    /// `shape = { disc = { centre = [x, y], radius = r } }`.
    Disc { centre: [f32; 2], radius: f32 },
    /// `shape = { polygon = [[x, y], ...] }`: the vertices in order, convex or concave.
    Polygon(Vec<[f32; 2]>),
}
