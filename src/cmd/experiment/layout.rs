//! Trail maps of case I, generated from a tree description.
//!
//! A [`TrailLayout`] is a tree of nodes (nest, bifurcations, numbered end points), each with a position
//! and the heading of the trail through it. Every edge is a cubic Bezier curve from parent to child,
//! sampled into a polyline. At a bifurcation both child edges leave at `fork_half_angle` on either side
//! of the parent's heading (a symmetric fork at a clear angle, which is what the bifurcation detection
//! of Algorithm 1 relies on: see `colcos_sim::behaviour::paper::foraging`) and bend smoothly toward
//! their child.
//!
//! From the layout and the set of available food points come the three static injection maps of
//! Table I (each a single polyline, so overlapping trail pieces do not add up):
//!
//! * LAP (blue): every edge;
//! * SAP (green): the edges on the paths from the nest to the available food points;
//! * SRP (red): at every bifurcation on those paths whose other branch leads to no food, a short piece of
//!   that branch from `srp_start` to `srp_end` metres along it (magenta over the blue).
use colcos_sim::Vec2;
use colcos_sim::scenario::{MapSpec, PheromoneSpec, RobotGroupSpec, ScenarioBuilder, ScenarioSpec};

/// One node of a trail tree.
#[derive(Clone, Debug, PartialEq)]
pub struct TrailNode {
    /// Position, m.
    pub pos: Vec2,
    /// Heading of the trail through the node, degrees counter-clockwise from +x.
    pub heading_deg: f32,
    /// Parent node (`None` for the nest).
    pub parent: Option<usize>,
}

/// How an edge turns from its fork toward its child.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Corners {
    /// A smooth cubic Bezier curve.
    #[default]
    Rounded,
    /// Straight segments with sharp corners, as a user draws a polyline: out of the fork along the
    /// branch's angle, straight to the start of the approach, then the approach.
    Straight,
}

/// A tree of trails from a nest to numbered end points.
#[derive(Clone, Debug, PartialEq)]
pub struct TrailLayout {
    pub name: String,
    /// Node 0 is the nest.
    pub nodes: Vec<TrailNode>,
    /// The end points in their numbering order: `ends[k]` is end point `k + 1`.
    pub ends: Vec<usize>,
    /// Half the angle between the two branches where they leave a bifurcation, degrees.
    pub fork_half_angle_deg: f32,
    /// Trail width, m.
    pub width: f32,
    /// Arena (screen) size, m.
    pub arena: Vec2,
    /// SRP piece along an unrewarding branch, from this many metres after the fork...
    pub srp_start: f32,
    /// ...to this many.
    pub srp_end: f32,
    pub corners: Corners,
}

/// Length of the straight run at the end of every edge, m.
pub const APPROACH: f32 = 0.08;

/// The paper's 65-inch screen, m.
pub const SCREEN: [f32; 2] = [1.439, 0.809];

/// One horizontal band of a generated layout.
#[derive(Clone, Copy, Debug)]
struct Band {
    y: f32,
    /// 2 or 3 end points.
    leaves: usize,
    /// The first end point's branch leaves toward +y (else -y).
    first_up: bool,
}

/// A band at height `y` with `leaves` end points, the first one's branch toward +y if `first_up`.
const fn band(y: f32, leaves: usize, first_up: bool) -> Band {
    Band {
        y,
        leaves,
        first_up,
    }
}

/// Builds a layout of four bands in a tree of two levels: nest -> A -> (upper, lower) -> two bands
/// each; in each band a first fork sends one branch to an end point and the other on to a second fork
/// with two more (or, for a two-leaf band, straight to an end point). `mirror` grows the tree leftward
/// from a nest on the right.
fn banded(name: &str, bands: [Band; 4], mirror: bool) -> TrailLayout {
    let w = SCREEN[0];
    let mut nodes: Vec<TrailNode> = Vec::new();
    let mut add = |x: f32, y: f32, parent: Option<usize>| -> usize {
        let (x, h) = if mirror { (w - x, 180.0) } else { (x, 0.0) };
        nodes.push(TrailNode {
            pos: Vec2::new(x, y),
            heading_deg: h,
            parent,
        });
        nodes.len() - 1
    };
    let root_y = 0.5 * (bands[1].y + bands[2].y);
    let nest = add(0.05, root_y, None);
    let a = add(0.17, root_y, Some(nest));
    let upper = add(0.44, 0.5 * (bands[2].y + bands[3].y), Some(a));
    let lower = add(0.44, 0.5 * (bands[0].y + bands[1].y), Some(a));
    let mut ends = Vec::new();
    // Top band first so that end points are numbered from the top.
    for (k, band) in bands.iter().enumerate().rev() {
        let parent = if k >= 2 { upper } else { lower };
        let f1 = add(0.70, band.y, Some(parent));
        let s = if band.first_up { 1.0 } else { -1.0 };
        let first = add(0.92, band.y + s * 0.055, Some(f1));
        ends.push(first);
        if band.leaves >= 3 {
            let f2 = add(1.00, band.y - s * 0.02, Some(f1));
            let b = add(1.30, band.y - s * 0.02 + 0.05, Some(f2));
            let c = add(1.30, band.y - s * 0.02 - 0.05, Some(f2));
            ends.extend([b, c]);
        } else {
            let b = add(1.20, band.y - s * 0.03, Some(f1));
            ends.push(b);
        }
    }
    TrailLayout {
        name: name.into(),
        nodes,
        ends,
        fork_half_angle_deg: 35.0,
        width: 0.04,
        arena: Vec2::from(SCREEN),
        srp_start: 0.03,
        srp_end: 0.15,
        corners: Corners::Rounded,
    }
}

impl TrailLayout {
    /// The default layout: nest on the left, twelve end points (the paper's food example: 3 and 10).
    pub fn a() -> Self {
        banded(
            "A",
            [
                band(0.125, 3, true),
                band(0.315, 3, true),
                band(0.505, 3, true),
                band(0.695, 3, true),
            ],
            false,
        )
    }

    /// The second layout: mirrored (nest on the right), eleven end points, first branches alternating.
    pub fn b() -> Self {
        banded(
            "B",
            [
                band(0.13, 3, true),
                band(0.33, 3, false),
                band(0.50, 2, true),
                band(0.70, 3, false),
            ],
            true,
        )
    }

    /// A layout by name (`"A"` or `"B"`, case-insensitive).
    pub fn by_name(name: &str) -> Option<Self> {
        match name.to_ascii_uppercase().as_str() {
            "A" => Some(Self::a()),
            "B" => Some(Self::b()),
            _ => None,
        }
    }

    /// The default food points of this layout (1-based end point numbers).
    pub fn default_foods(&self) -> Vec<usize> {
        match self.name.as_str() {
            "B" => vec![4, 10],
            _ => vec![3, 10],
        }
    }

    pub fn nest(&self) -> &TrailNode {
        &self.nodes[0]
    }

    /// Children of node `i`, ordered counter-clockwise last (the first is on the right of the parent's
    /// heading).
    pub fn children(&self, i: usize) -> Vec<usize> {
        let mut c: Vec<usize> = (0..self.nodes.len())
            .filter(|&k| self.nodes[k].parent == Some(i))
            .collect();
        let n = &self.nodes[i];
        let h = Vec2::from_angle(n.heading_deg.to_radians());
        c.sort_by(|&a, &b| {
            let side = |k: usize| h.perp_dot(self.nodes[k].pos - n.pos);
            side(a).total_cmp(&side(b))
        });
        c
    }

    /// Positions of the end points, in numbering order.
    pub fn end_points(&self) -> Vec<Vec2> {
        self.ends.iter().map(|&k| self.nodes[k].pos).collect()
    }

    /// The polyline of the edge into node `child` (from its parent), sampled every ~1 cm.
    pub fn edge(&self, child: usize) -> Vec<Vec2> {
        let c = &self.nodes[child];
        let Some(pi) = c.parent else {
            return vec![c.pos];
        };
        let p = &self.nodes[pi];
        let siblings = self.children(pi);
        let h0 = p.heading_deg.to_radians();
        let start = if siblings.len() >= 2 {
            let half = self.fork_half_angle_deg.to_radians();
            // The right-most child leaves to the right (-), the left-most to the left (+).
            if siblings[0] == child {
                h0 - half
            } else {
                h0 + half
            }
        } else {
            h0
        };
        // A Bezier curve, then a straight run of `APPROACH` into the child along its heading, so that a
        // robot reaches the next bifurcation centred and aligned.
        let end_dir = Vec2::from_angle(c.heading_deg.to_radians());
        let (p0, p3) = (p.pos, c.pos - end_dir * APPROACH);
        let len = p0.distance(p3);
        let a = 0.3 * len;
        let p1 = p0 + Vec2::from_angle(start) * a;
        if self.corners == Corners::Straight {
            return densify(&[p0, p1, p3, c.pos], 0.01);
        }
        let p2 = p3 - end_dir * a;
        let n = ((len / 0.01).ceil() as usize).max(2);
        let mut pts: Vec<Vec2> = (0..=n)
            .map(|k| {
                let t = k as f32 / n as f32;
                let u = 1.0 - t;
                p0 * (u * u * u)
                    + p1 * (3.0 * u * u * t)
                    + p2 * (3.0 * u * t * t)
                    + p3 * (t * t * t)
            })
            .collect();
        pts.push(c.pos);
        pts
    }

    /// All edges as (child node, polyline).
    pub fn edges(&self) -> Vec<(usize, Vec<Vec2>)> {
        (1..self.nodes.len()).map(|k| (k, self.edge(k))).collect()
    }

    /// Nodes on the path from the nest to node `k` (inclusive).
    pub fn path_to(&self, mut k: usize) -> Vec<usize> {
        let mut path = vec![k];
        while let Some(p) = self.nodes[k].parent {
            path.push(p);
            k = p;
        }
        path.reverse();
        path
    }

    /// Marks the nodes whose incoming edge is on a path from the nest to one of `foods` (1-based).
    fn rewarded(&self, foods: &[usize]) -> Vec<bool> {
        let mut on = vec![false; self.nodes.len()];
        for &f in foods {
            if let Some(&end) = self.ends.get(f.wrapping_sub(1)) {
                for k in self.path_to(end) {
                    on[k] = true;
                }
            }
        }
        on
    }

    /// A depth-first walk over the edges whose child satisfies `keep`, as one polyline that goes down
    /// each kept edge and back up it (so one polyline map covers a whole subtree without overlaps adding).
    fn tour(&self, keep: &dyn Fn(usize) -> bool) -> Vec<Vec2> {
        fn walk(l: &TrailLayout, node: usize, keep: &dyn Fn(usize) -> bool, out: &mut Vec<Vec2>) {
            for c in l.children(node) {
                if !keep(c) {
                    continue;
                }
                let e = l.edge(c);
                out.extend(e.iter().skip(1));
                walk(l, c, keep, out);
                out.extend(e.iter().rev().skip(1));
            }
        }
        let mut out = vec![self.nest().pos];
        walk(self, 0, keep, &mut out);
        out
    }

    /// LAP polyline: the whole tree.
    pub fn lap_polyline(&self) -> Vec<Vec2> {
        self.tour(&|_| true)
    }

    /// SAP polyline: the paths to `foods` (1-based end point numbers).
    pub fn sap_polyline(&self, foods: &[usize]) -> Vec<Vec2> {
        let on = self.rewarded(foods);
        self.tour(&|k| on[k])
    }

    /// SRP pieces: at each bifurcation on a rewarded path, the start of each unrewarded branch.
    pub fn srp_polylines(&self, foods: &[usize]) -> Vec<Vec<Vec2>> {
        let on = self.rewarded(foods);
        let mut out = Vec::new();
        for k in 0..self.nodes.len() {
            if !on[k] {
                continue;
            }
            for c in self.children(k) {
                if on[c] {
                    continue;
                }
                let e = self.edge(c);
                let piece = clip_by_length(&e, self.srp_start, self.srp_end);
                if piece.len() >= 2 {
                    out.push(piece);
                }
            }
        }
        out
    }

    /// The scenario of one case-I group: `pheromones` is a subset of `["LAP", "SAP", "SRP"]`; one robot
    /// at the nest heading along the trunk, behaviour `forage`. Table I: e = 50 s, d = 0, J from the
    /// maps (steady state `e J = 1`, drawn at full level 255), pre-loaded at t = 0 (`preload`).
    pub fn scenario_spec(
        &self,
        foods: &[usize],
        pheromones: &[&str],
        seed: u64,
        duration: f32,
        cell: f32,
    ) -> ScenarioSpec {
        let rate = 1.0 / 50.0;
        let map = |points: Vec<Vec2>, width: f32| {
            let points = points.iter().map(|p| [round5(p.x), round5(p.y)]).collect();
            MapSpec::polyline(points, width, rate)
        };
        let nest = self.nest();
        let mut scenario = ScenarioBuilder::new()
            .name(format!("case1_{}_{}", self.name, pheromones.join("_")))
            .duration(duration)
            .seed(seed)
            .with(|s| s.screen.size = SCREEN)
            .cell(cell)
            .gif_interval(0.0);
        for &name in pheromones {
            let (colour, maps) = match name {
                "LAP" => (
                    [0.0, 0.0, 255.0],
                    vec![map(self.lap_polyline(), self.width)],
                ),
                "SAP" => (
                    [0.0, 255.0, 0.0],
                    vec![map(self.sap_polyline(foods), self.width)],
                ),
                "SRP" => (
                    [255.0, 0.0, 0.0],
                    self.srp_polylines(foods)
                        .into_iter()
                        .map(|p| map(p, self.width))
                        .collect(),
                ),
                other => panic!("unknown case-I pheromone {other:?}"),
            };
            scenario = scenario.pheromone(PheromoneSpec {
                maps,
                preload: true,
                ..PheromoneSpec::grid(name, colour).with_evaporation(50.0)
            });
        }
        scenario
            .robots(
                RobotGroupSpec::new(1, "forage")
                    .with_role("forager")
                    .at_poses(vec![[nest.pos.x, nest.pos.y, nest.heading_deg]]),
            )
            .spec()
    }
}

/// `pts` with points added so that no two consecutive ones are more than `step` apart.
fn densify(pts: &[Vec2], step: f32) -> Vec<Vec2> {
    let mut out = vec![pts[0]];
    for w in pts.windows(2) {
        let n = ((w[0].distance(w[1]) / step).ceil() as usize).max(1);
        out.extend((1..=n).map(|k| w[0].lerp(w[1], k as f32 / n as f32)));
    }
    out
}

fn round5(v: f32) -> f32 {
    (v * 1e5).round() / 1e5
}

/// The part of polyline `pts` between arc lengths `s0` and `s1`.
pub fn clip_by_length(pts: &[Vec2], s0: f32, s1: f32) -> Vec<Vec2> {
    let mut out = Vec::new();
    let mut s = 0.0;
    for w in pts.windows(2) {
        let (a, b) = (w[0], w[1]);
        let l = a.distance(b);
        let (t0, t1) = ((s0 - s) / l.max(1e-9), (s1 - s) / l.max(1e-9));
        if t1 >= 0.0 && t0 <= 1.0 {
            let (u0, u1) = (t0.clamp(0.0, 1.0), t1.clamp(0.0, 1.0));
            if out.is_empty() {
                out.push(a.lerp(b, u0));
            }
            out.push(a.lerp(b, u1));
        }
        s += l;
    }
    out
}
