//! Random trail maps of case I by the paper's rule, as a researcher would draw their own arena.
//!
//! A nest on one side of the screen (left, right, bottom or top, anywhere along its middle half) sends
//! a trunk to a first bifurcation; every bifurcation has two branches leaving at +-35 degrees from the
//! parent's heading (`TrailLayout::fork_half_angle_deg`), each bending by up to 35 degrees back toward
//! the parent's heading or 10 degrees further out; a branch forks again or ends, down to a random depth
//! of 2-4 bifurcation levels (at least one path reaches it), with random lengths. One to three end
//! points are food. Half the maps are drawn with rounded corners, half with straight segments
//! ([`Corners`]). The LAP, SAP and SRP maps come from [`TrailLayout`] as for layouts A and B.
//!
//! A drawn map is kept only if it fits ([`check_fit`]): every trail point at least `margin` from the
//! screen's edge, every branch long enough for its SRP piece, and any two trails at least `clearance`
//! apart (centre lines) except within `near_fork` of the node they share; otherwise it is drawn again.
use super::layout::{Corners, SCREEN, TrailLayout, TrailNode};
use anyhow::{Result, bail};
use colcos_sim::Vec2;
use colcos_sim::rng::{SimRng, stream};
use rand::RngExt;

/// The rules a generated map obeys.
#[derive(Clone, Debug)]
pub struct MapRules {
    /// Bifurcation levels, inclusive range.
    pub depth: (usize, usize),
    /// Food points, inclusive range.
    pub foods: (usize, usize),
    /// Half the angle between two branches at a fork, degrees (the paper's maps: 35).
    pub fork_half_angle_deg: f32,
    /// Distance of every trail point from the screen's edge, m.
    pub margin: f32,
    /// Distance between the centre lines of two trails, m.
    pub clearance: f32,
    /// Along two trails that share a node, points closer than this to it (along the trail) are not
    /// compared, m.
    pub near_fork: f32,
    /// Shortest branch (after a fork), m: the SRP piece (3-15 cm) and the approach must fit.
    pub min_branch: f32,
    /// Shortest trunk, m.
    pub min_trunk: f32,
    /// Probability that a branch above the deepest level forks again.
    pub p_continue: f32,
    /// Draws before giving up.
    pub max_attempts: usize,
}

impl Default for MapRules {
    fn default() -> Self {
        MapRules {
            depth: (2, 4),
            foods: (1, 3),
            fork_half_angle_deg: 35.0,
            margin: 0.05,
            clearance: 0.08,
            near_fork: 0.10,
            min_branch: 0.17,
            min_trunk: 0.12,
            p_continue: 0.6,
            max_attempts: 5000,
        }
    }
}

/// One generated map: the layout, its food points (1-based end point numbers) and how it was drawn.
#[derive(Clone, Debug)]
pub struct RandomMap {
    pub layout: TrailLayout,
    pub foods: Vec<usize>,
    /// Bifurcation levels of the deepest path.
    pub depth: usize,
    /// Draws it took (the rejected ones did not fit).
    pub attempts: usize,
}

/// Stream id of the map generator (apart from every world's streams: the seed is mixed with it).
const MAP_STREAM: u64 = 0x6d61_7073;

/// Map `index` of the maps of `seed` (deterministic: the same pair always gives the same map).
pub fn random_map(seed: u64, index: usize, rules: &MapRules) -> Result<RandomMap> {
    let mut rng = stream(seed, index as u64, MAP_STREAM);
    // The nest's side and the depth are drawn once, so rejections do not favour the easy ones.
    let side = rng.random_range(0..4usize);
    let depth = rng.random_range(rules.depth.0..=rules.depth.1);
    for attempt in 1..=rules.max_attempts {
        let mut layout = draw(&mut rng, rules, side, depth);
        layout.name = format!("R{index}");
        if check_fit(&layout, rules).is_err() {
            continue;
        }
        let n_ends = layout.ends.len();
        let n_food = rng
            .random_range(rules.foods.0..=rules.foods.1)
            .min(n_ends - 1);
        let mut foods: Vec<usize> = (1..=n_ends).collect();
        // A partial Fisher-Yates shuffle picks the food points.
        for k in 0..n_food {
            let j = rng.random_range(k..n_ends);
            foods.swap(k, j);
        }
        foods.truncate(n_food);
        foods.sort_unstable();
        return Ok(RandomMap {
            layout,
            foods,
            depth,
            attempts: attempt,
        });
    }
    bail!(
        "no random trail map of seed {seed}, index {index} fitted the {:.3} x {:.3} m screen in {} draws",
        SCREEN[0],
        SCREEN[1],
        rules.max_attempts
    )
}

/// Maps `0..count` of `seed`.
pub fn random_maps(seed: u64, count: usize, rules: &MapRules) -> Result<Vec<RandomMap>> {
    (0..count).map(|i| random_map(seed, i, rules)).collect()
}

fn uniform(rng: &mut SimRng, lo: f32, hi: f32) -> f32 {
    lo + (hi - lo) * rng.random::<f32>()
}

/// One draw (not yet checked) with the nest on `side` (left, right, bottom, top) and `depth` levels.
fn draw(rng: &mut SimRng, rules: &MapRules, side: usize, depth: usize) -> TrailLayout {
    let size = Vec2::from(SCREEN);
    // Heading into the screen from each side, and the extent the tree can grow along it.
    let (heading, extent, across) = match side {
        0 => (0.0f32, size.x, size.y),
        1 => (180.0, size.x, size.y),
        2 => (90.0, size.y, size.x),
        _ => (270.0, size.y, size.x),
    };
    let t = uniform(rng, 0.25, 0.75);
    let inset = rules.margin;
    let nest = match side {
        0 => Vec2::new(inset, t * size.y),
        1 => Vec2::new(size.x - inset, t * size.y),
        2 => Vec2::new(t * size.x, inset),
        _ => Vec2::new(t * size.x, size.y - inset),
    };
    // Advance along the growth direction per level: the deepest path spans at most the screen, and the
    // tree's spread across it (which grows with the depth) fits.
    let room = (extent - 2.0 * rules.margin) / (depth as f32 + 0.7);
    let level = room.min((across - 2.0 * rules.margin) / depth as f32);
    let trunk = uniform(rng, 0.4, 0.9)
        .mul_add(level, 0.0)
        .max(rules.min_trunk);
    let mut nodes = vec![TrailNode {
        pos: nest,
        heading_deg: heading,
        parent: None,
    }];
    nodes.push(TrailNode {
        pos: nest + Vec2::from_angle(heading.to_radians()) * trunk,
        heading_deg: heading,
        parent: Some(0),
    });
    let g = Growth {
        rules,
        depth,
        level,
        heading0: heading,
    };
    g.grow(rng, &mut nodes, 1, 1, true);
    let corners = if rng.random::<f32>() < 0.5 {
        Corners::Rounded
    } else {
        Corners::Straight
    };
    let mut layout = TrailLayout {
        name: String::new(),
        nodes,
        ends: Vec::new(),
        fork_half_angle_deg: rules.fork_half_angle_deg,
        width: 0.04,
        arena: size,
        srp_start: 0.03,
        srp_end: 0.15,
        corners,
    };
    layout.ends = leaves_in_order(&layout, 0);
    layout
}

struct Growth<'a> {
    rules: &'a MapRules,
    depth: usize,
    level: f32,
    heading0: f32,
}

impl Growth<'_> {
    /// Adds the two branches of fork `node` (at bifurcation level `lvl`); `deep`: one of them must
    /// continue to the deepest level.
    fn grow(
        &self,
        rng: &mut SimRng,
        nodes: &mut Vec<TrailNode>,
        node: usize,
        lvl: usize,
        deep: bool,
    ) {
        let half = self.rules.fork_half_angle_deg;
        let deep_side = rng.random_range(0..2usize);
        for (k, s) in [-1.0f32, 1.0].into_iter().enumerate() {
            let h = nodes[node].heading_deg;
            let leave = h + s * half;
            // Bend back toward the parent's heading (up to the full half-angle) or a little further out.
            let bend = s * uniform(rng, -half, 25.0);
            let mut child_h = leave + bend;
            // Keep the tree growing away from the nest.
            let dev = (child_h - self.heading0).clamp(-75.0, 75.0);
            child_h = self.heading0 + dev;
            let len = (uniform(rng, 0.6, 1.4) * self.level / 0.82).max(self.rules.min_branch);
            let dir = Vec2::from_angle((0.5 * (leave + child_h)).to_radians());
            let pos = nodes[node].pos + dir * len;
            nodes.push(TrailNode {
                pos,
                heading_deg: child_h,
                parent: Some(node),
            });
            let child = nodes.len() - 1;
            let must = deep && k == deep_side;
            let fork = lvl < self.depth && (must || rng.random::<f32>() < self.rules.p_continue);
            if fork {
                self.grow(rng, nodes, child, lvl + 1, must);
            }
        }
    }
}

/// The leaves under `node`, depth first, right-hand branches first (the layouts' numbering order).
fn leaves_in_order(l: &TrailLayout, node: usize) -> Vec<usize> {
    let children = l.children(node);
    if children.is_empty() {
        return vec![node];
    }
    children
        .into_iter()
        .flat_map(|c| leaves_in_order(l, c))
        .collect()
}

/// Checks a layout against the rules; the error says which rule it broke.
pub fn check_fit(l: &TrailLayout, rules: &MapRules) -> std::result::Result<(), String> {
    let edges = l.edges();
    let lo = Vec2::splat(rules.margin);
    let hi = l.arena - lo;
    for (child, pts) in &edges {
        if let Some(p) = pts.iter().find(|p| p.cmplt(lo).any() || p.cmpgt(hi).any()) {
            return Err(format!(
                "the trail into node {child} passes ({:.3}, {:.3}), within {} m of the screen's edge",
                p.x, p.y, rules.margin
            ));
        }
        let len: f32 = pts.windows(2).map(|w| w[0].distance(w[1])).sum();
        let min = if l.nodes[*child].parent == Some(0) {
            rules.min_trunk
        } else {
            rules.min_branch
        };
        if len < min {
            return Err(format!(
                "the trail into node {child} is {len:.3} m long (< {min})"
            ));
        }
    }
    // Arc length of every point from the start of its edge, and the edge's length.
    let arcs: Vec<Vec<f32>> = edges
        .iter()
        .map(|(_, pts)| {
            let mut s = 0.0;
            let mut out = vec![0.0];
            for w in pts.windows(2) {
                s += w[0].distance(w[1]);
                out.push(s);
            }
            out
        })
        .collect();
    for a in 0..edges.len() {
        for b in a + 1..edges.len() {
            let (ca, cb) = (edges[a].0, edges[b].0);
            let (pa, pb) = (l.nodes[ca].parent, l.nodes[cb].parent);
            // Where the two edges share a node: at the start (true) or the end (false) of each.
            let shared = if pa == pb {
                Some((true, true))
            } else if pb == Some(ca) {
                Some((false, true))
            } else if pa == Some(cb) {
                Some((true, false))
            } else {
                None
            };
            // Distance of point `i` of edge `k` from the shared node, along its edge.
            let from_shared = |k: usize, i: usize| -> f32 {
                let Some((sa, sb)) = shared else {
                    return f32::INFINITY;
                };
                let at_start = if k == a { sa } else { sb };
                let arc = &arcs[k];
                if at_start {
                    arc[i]
                } else {
                    arc[arc.len() - 1] - arc[i]
                }
            };
            for (i, p) in edges[a].1.iter().enumerate() {
                if from_shared(a, i) < rules.near_fork {
                    continue;
                }
                for (j, q) in edges[b].1.iter().enumerate() {
                    if from_shared(b, j) < rules.near_fork {
                        continue;
                    }
                    let d = p.distance(*q);
                    if d < rules.clearance {
                        return Err(format!(
                            "the trails into nodes {ca} and {cb} come {d:.3} m close (< {})",
                            rules.clearance
                        ));
                    }
                }
            }
        }
    }
    Ok(())
}

/// The expected share of arrivals at the food points for a robot that takes either branch of every
/// fork with probability 1/2 (G1, LAP only): the sum over the food points of `2^-forks on the path`.
pub fn coin_share(l: &TrailLayout, foods: &[usize]) -> f64 {
    foods
        .iter()
        .filter_map(|&f| l.ends.get(f.wrapping_sub(1)))
        .map(|&end| {
            let forks = l.path_to(end).len().saturating_sub(2);
            0.5f64.powi(forks as i32)
        })
        .sum()
}
