//! `[arena] shape`: a disc or polygon boundary inside the arena's rectangle, as a thin wall of capsules
//! (robots collide with it, bumpers see it) and an inside test (placement keeps robots within it).
use super::Obstacles;
use super::spec::ArenaShape;
use crate::error::{Result, SimError};
use glam::Vec2;
use parry2d::math::Pose;
use parry2d::shape::SharedShape;

/// Thickness of the boundary wall, m. Its inner face is the shape's edge.
pub const BOUNDARY_THICKNESS: f32 = 0.004;
/// Segments of a disc boundary.
const DISC_SEGMENTS: usize = 96;
/// Obstacle index of the boundary's parts (not an `[[obstacles]]` entry).
pub const BOUNDARY: u32 = u32::MAX;

/// Where robots may be: inside the disc, or inside the polygon (counter-clockwise vertices).
#[derive(Clone, Debug)]
pub enum Inside {
    Disc { centre: Vec2, radius: f32 },
    Polygon(Vec<Vec2>),
}

impl Inside {
    /// Whether a disc of `radius` at `p` lies wholly inside.
    pub fn holds(&self, p: Vec2, radius: f32) -> bool {
        match self {
            Inside::Disc {
                centre,
                radius: big,
            } => p.distance(*centre) <= big - radius,
            Inside::Polygon(v) => {
                let n = v.len();
                // Even-odd crossing count, then the distance to every edge.
                let mut inside = false;
                for k in 0..n {
                    let (a, b) = (v[k], v[(k + 1) % n]);
                    if (a.y > p.y) != (b.y > p.y)
                        && p.x < a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x)
                    {
                        inside = !inside;
                    }
                }
                inside
                    && (0..n).all(|k| {
                        let (a, b) = (v[k], v[(k + 1) % n]);
                        let t = ((p - a).dot(b - a) / (b - a).length_squared()).clamp(0.0, 1.0);
                        // The wall is centred on the edge: half its thickness lies inside.
                        p.distance(a + t * (b - a)) >= radius + 0.5 * BOUNDARY_THICKNESS
                    })
            }
        }
    }
}

/// Adds the boundary of `shape` to `out` (parts, outline, inside test), checking it against the
/// arena's rectangle `arena`. Errors name `arena.shape`.
pub(super) fn add(out: &mut Obstacles, shape: &ArenaShape, arena: Vec2) -> Result<()> {
    let key = "arena.shape";
    let half = 0.5 * BOUNDARY_THICKNESS;
    let (ring, inside) = match shape {
        ArenaShape::Disc { centre, radius } => {
            let c = Vec2::from(*centre);
            let r = *radius;
            let shown = format!("{{ disc = {{ centre = {centre:?}, radius = {r} }} }}");
            if !(c.is_finite() && r.is_finite() && r > 0.0) {
                return Err(SimError::invalid(
                    key,
                    shown,
                    "the centre must be finite and the radius positive",
                ));
            }
            let reach = r + BOUNDARY_THICKNESS;
            if c.x - reach < 0.0
                || c.y - reach < 0.0
                || c.x + reach > arena.x
                || c.y + reach > arena.y
            {
                return Err(SimError::invalid(
                    key,
                    shown,
                    format!(
                        "the disc and its {BOUNDARY_THICKNESS} m wall reach outside the arena \
                         [0, {}] x [0, {}] m",
                        arena.x, arena.y
                    ),
                ));
            }
            // The wall's centre line sits half a thickness outside the radius: its inner face is
            // the disc's edge.
            let ring: Vec<Vec2> = (0..DISC_SEGMENTS)
                .map(|k| {
                    c + (r + half)
                        * Vec2::from_angle(k as f32 * std::f32::consts::TAU / DISC_SEGMENTS as f32)
                })
                .collect();
            (
                ring,
                Inside::Disc {
                    centre: c,
                    radius: r,
                },
            )
        }
        ArenaShape::Polygon(points) => {
            let shown = format!(
                "{{ polygon = [{}] }}",
                points
                    .iter()
                    .map(|p| format!("[{}, {}]", p[0], p[1]))
                    .collect::<Vec<_>>()
                    .join(", ")
            );
            if !points.as_flattened().iter().all(|x| x.is_finite()) {
                return Err(SimError::invalid(key, shown, "the points must be finite"));
            }
            let mut v: Vec<Vec2> = points.iter().map(|&p| Vec2::from(p)).collect();
            super::shapes::polygon_checks(key, &shown, &v)?;
            if super::shapes::signed_area(&v) < 0.0 {
                v.reverse();
            }
            if let Some(p) = v
                .iter()
                .find(|p| p.x < 0.0 || p.y < 0.0 || p.x > arena.x || p.y > arena.y)
            {
                return Err(SimError::invalid(
                    key,
                    shown,
                    format!(
                        "point [{}, {}] lies outside the arena [0, {}] x [0, {}] m",
                        p.x, p.y, arena.x, arena.y
                    ),
                ));
            }
            (v.clone(), Inside::Polygon(v))
        }
    };
    let n = ring.len();
    for k in 0..n {
        let (a, b) = (ring[k], ring[(k + 1) % n]);
        let first = out.parts.len();
        out.push(0, SharedShape::capsule(a, b, half), Pose::IDENTITY);
        out.parts[first].obstacle = BOUNDARY;
    }
    out.outlines.push((BOUNDARY as usize, ring));
    out.inside = Some(inside);
    Ok(())
}
