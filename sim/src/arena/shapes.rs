//! `[[obstacles]]` entries to parry2d shapes, refusing what cannot be simulated with an error naming
//! the key: missing or stray keys, degenerate shapes, shapes reaching outside the arena.
use super::Obstacles;
use super::mask;
use super::spec::{ObstacleKind, ObstacleShape, ObstacleSpec};
use crate::error::{Result, SimError};
use glam::Vec2;
use parry2d::math::Pose;
use parry2d::shape::{SharedShape, TriMesh};
use parry2d::transformation::hertel_mehlhorn;
use std::path::Path;

/// How far a shape may reach past the arena's edge (rounding of rotated boxes and discs), m.
const EDGE_SLACK: f32 = 1e-4;
/// Vertices on a drawn disc outline.
const DISC_OUTLINE: usize = 48;

fn fmt_points(p: &[[f32; 2]]) -> String {
    let items: Vec<String> = p.iter().map(|q| format!("[{}, {}]", q[0], q[1])).collect();
    format!("[{}]", items.join(", "))
}

fn finite(key: &str, v: &[f32], shown: String) -> Result<()> {
    if v.iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(SimError::invalid(key, shown, "must be finite"))
    }
}

/// Appends the parts and outline of obstacle `i` (`spec`) to `out`, checking it against an arena of
/// `arena` size; image paths resolve against `base_dir`.
pub(super) fn add(
    out: &mut Obstacles,
    i: usize,
    spec: &ObstacleSpec,
    arena: Vec2,
    base_dir: &Path,
) -> Result<()> {
    let key = |k: &str| format!("obstacles[{i}].{k}");
    let shape_name = format!("{:?}", spec.shape).to_lowercase();
    // Keys that belong to other shapes are errors: a typo'd shape must not silently drop them.
    let used: &[&str] = match spec.shape {
        ObstacleShape::Box => &["centre", "size", "angle"],
        ObstacleShape::Disc => &["centre", "radius"],
        ObstacleShape::Polygon => &["points"],
        ObstacleShape::Wall => &["points", "thickness"],
        ObstacleShape::Mask => &["image", "channel", "threshold", "pixels"],
    };
    let present = [
        ("centre", spec.centre.is_some()),
        ("size", spec.size.is_some()),
        ("angle", spec.angle.is_some()),
        ("radius", spec.radius.is_some()),
        ("points", spec.points.is_some()),
        ("thickness", spec.thickness.is_some()),
        ("image", spec.image.is_some()),
        ("channel", spec.channel.is_some()),
        ("threshold", spec.threshold.is_some()),
        ("pixels", spec.pixels.is_some()),
    ];
    for (k, is) in present {
        if is && !used.contains(&k) {
            return Err(SimError::invalid(
                key(k),
                "(set)",
                format!("a {shape_name} obstacle takes only {used:?}"),
            ));
        }
    }
    let need = |k: &str| {
        SimError::invalid(
            key(k),
            "(missing)",
            format!("a {shape_name} obstacle needs it"),
        )
    };
    if spec.colour.is_some() && spec.kind != ObstacleKind::Printed {
        return Err(SimError::invalid(
            key("colour"),
            "(set)",
            "only a printed obstacle (kind = \"printed\") is drawn in a colour",
        ));
    }
    let first_part = out.parts.len();
    match spec.shape {
        ObstacleShape::Box => {
            let c = spec.centre.ok_or_else(|| need("centre"))?;
            let s = spec.size.ok_or_else(|| need("size"))?;
            let angle = spec.angle.unwrap_or(0.0);
            finite(&key("centre"), &c, format!("{c:?}"))?;
            finite(&key("angle"), &[angle], format!("{angle}"))?;
            if !(s[0] > 0.0 && s[1] > 0.0 && s[0].is_finite() && s[1].is_finite()) {
                return Err(SimError::invalid(
                    key("size"),
                    format!("{s:?}"),
                    "width and height must be positive and finite",
                ));
            }
            let pose = Pose::new(Vec2::from(c), angle.to_radians());
            let half = Vec2::from(s) * 0.5;
            out.push(i, SharedShape::cuboid(half.x, half.y), pose);
            let corners = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
                .map(|(x, y)| pose.transform_point(Vec2::new(x * half.x, y * half.y)));
            out.outlines.push((i, corners.to_vec()));
        }
        ObstacleShape::Disc => {
            let c = spec.centre.ok_or_else(|| need("centre"))?;
            let r = spec.radius.ok_or_else(|| need("radius"))?;
            finite(&key("centre"), &c, format!("{c:?}"))?;
            if !(r > 0.0 && r.is_finite()) {
                return Err(SimError::invalid(
                    key("radius"),
                    r,
                    "must be positive and finite",
                ));
            }
            let c = Vec2::from(c);
            out.push(i, SharedShape::ball(r), Pose::from_translation(c));
            let ring = (0..DISC_OUTLINE)
                .map(|k| {
                    c + r * Vec2::from_angle(k as f32 * std::f32::consts::TAU / DISC_OUTLINE as f32)
                })
                .collect();
            out.outlines.push((i, ring));
        }
        ObstacleShape::Polygon => {
            let pts = spec.points.as_ref().ok_or_else(|| need("points"))?;
            let shown = fmt_points(pts);
            finite(&key("points"), pts.as_flattened(), shown.clone())?;
            let mut v: Vec<Vec2> = pts.iter().map(|&p| Vec2::from(p)).collect();
            polygon_checks(&key("points"), &shown, &v)?;
            if signed_area(&v) < 0.0 {
                v.reverse();
            }
            let degenerate =
                || SimError::invalid(key("points"), &shown, "parry2d cannot build this polygon");
            let pieces = if is_convex(&v) {
                vec![v.clone()]
            } else {
                let mesh = TriMesh::from_polygon(v.clone()).ok_or_else(degenerate)?;
                hertel_mehlhorn(mesh.vertices(), mesh.indices())
            };
            for piece in pieces {
                let shape = SharedShape::convex_polyline(piece).ok_or_else(degenerate)?;
                out.push(i, shape, Pose::IDENTITY);
            }
            out.outlines.push((i, v));
        }
        ObstacleShape::Wall => {
            let pts = spec.points.as_ref().ok_or_else(|| need("points"))?;
            let t = spec.thickness.ok_or_else(|| need("thickness"))?;
            let shown = fmt_points(pts);
            finite(&key("points"), pts.as_flattened(), shown.clone())?;
            if !(t > 0.0 && t.is_finite()) {
                return Err(SimError::invalid(
                    key("thickness"),
                    t,
                    "must be positive and finite",
                ));
            }
            if pts.len() < 2 {
                return Err(SimError::invalid(
                    key("points"),
                    shown,
                    "a wall needs at least 2 points",
                ));
            }
            for (k, w) in pts.windows(2).enumerate() {
                let (a, b) = (Vec2::from(w[0]), Vec2::from(w[1]));
                if a.distance(b) < 1e-6 {
                    return Err(SimError::invalid(
                        key(&format!("points[{}]", k + 1)),
                        format!("[{}, {}]", b.x, b.y),
                        "repeats the point before it (a wall segment of zero length)",
                    ));
                }
                out.push(i, SharedShape::capsule(a, b, 0.5 * t), Pose::IDENTITY);
                let n = (b - a).normalize().perp() * (0.5 * t);
                out.outlines.push((i, vec![a - n, b - n, b + n, a + n]));
            }
        }
        ObstacleShape::Mask => {
            let image = spec.image.as_ref().ok_or_else(|| need("image"))?;
            let rects = mask::solid_rects(
                &key("image"),
                &base_dir.join(image),
                spec.channel,
                spec.threshold.unwrap_or(128),
                spec.pixels,
                &key,
            )?;
            if rects.is_empty() {
                return Err(SimError::invalid(
                    key("threshold"),
                    spec.threshold.unwrap_or(128),
                    format!("no pixel of {image} reaches it: the mask is empty"),
                ));
            }
            for r in rects {
                // Pixel rectangles (row 0 at the top) to arena metres (y up).
                let lo = Vec2::new(r.x0 * arena.x, (1.0 - r.y1) * arena.y);
                let hi = Vec2::new(r.x1 * arena.x, (1.0 - r.y0) * arena.y);
                let half = 0.5 * (hi - lo);
                let pose = Pose::from_translation(0.5 * (lo + hi));
                out.push(i, SharedShape::cuboid(half.x, half.y), pose);
                out.outlines.push((
                    i,
                    vec![lo, Vec2::new(hi.x, lo.y), hi, Vec2::new(lo.x, hi.y)],
                ));
            }
        }
    }
    // Every part must lie in the arena: a shape past the walls is a typo or wrong units.
    for part in &out.parts[first_part..] {
        if part.lo.x < -EDGE_SLACK
            || part.lo.y < -EDGE_SLACK
            || part.hi.x > arena.x + EDGE_SLACK
            || part.hi.y > arena.y + EDGE_SLACK
        {
            let shown = match spec.shape {
                ObstacleShape::Box | ObstacleShape::Disc => {
                    format!("{:?}", spec.centre.unwrap_or_default())
                }
                _ => format!(
                    "[{}, {}] .. [{}, {}]",
                    part.lo.x, part.lo.y, part.hi.x, part.hi.y
                ),
            };
            let k = match spec.shape {
                ObstacleShape::Box | ObstacleShape::Disc => "centre",
                ObstacleShape::Mask => "image",
                _ => "points",
            };
            return Err(SimError::invalid(
                key(k),
                shown,
                format!(
                    "the {shape_name} reaches outside the arena [0, {}] x [0, {}] m \
                     (its bounds are [{:.4}, {:.4}] .. [{:.4}, {:.4}])",
                    arena.x, arena.y, part.lo.x, part.lo.y, part.hi.x, part.hi.y
                ),
            ));
        }
    }
    Ok(())
}

/// Twice the signed area (positive counter-clockwise).
pub(super) fn signed_area(v: &[Vec2]) -> f32 {
    let n = v.len();
    (0..n).map(|k| v[k].perp_dot(v[(k + 1) % n])).sum::<f32>()
}

fn is_convex(v: &[Vec2]) -> bool {
    let n = v.len();
    (0..n).all(|k| {
        let (a, b, c) = (v[k], v[(k + 1) % n], v[(k + 2) % n]);
        (b - a).perp_dot(c - b) >= 0.0
    })
}

/// At least 3 distinct points, no two edges crossing and a non-zero area.
pub(super) fn polygon_checks(key: &str, shown: &str, v: &[Vec2]) -> Result<()> {
    let bad = |reason: String| Err(SimError::invalid(key, shown, reason));
    let n = v.len();
    if n < 3 {
        return bad(format!("a polygon needs at least 3 points, not {n}"));
    }
    for k in 0..n {
        if v[k].distance(v[(k + 1) % n]) < 1e-6 {
            return bad(format!("points {k} and {} coincide", (k + 1) % n));
        }
    }
    let cross = |a: Vec2, b: Vec2, c: Vec2, d: Vec2| {
        let o = |p: Vec2, q: Vec2, r: Vec2| (q - p).perp_dot(r - p);
        o(a, b, c) * o(a, b, d) < 0.0 && o(c, d, a) * o(c, d, b) < 0.0
    };
    for i in 0..n {
        for j in i + 2..n {
            if i == 0 && j == n - 1 {
                continue;
            }
            if cross(v[i], v[(i + 1) % n], v[j], v[(j + 1) % n]) {
                return bad(format!(
                    "edges {i}-{} and {j}-{} cross (the polygon must not intersect itself)",
                    (i + 1) % n,
                    (j + 1) % n
                ));
            }
        }
    }
    // Below a square of 0.1 mm (rounding of collinear points leaves ~1e-9).
    if signed_area(v).abs() < 1e-8 {
        return bad("the polygon has no area (its points are on a line)".into());
    }
    Ok(())
}
