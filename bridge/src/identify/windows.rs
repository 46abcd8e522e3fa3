//! What the poses say each robot did between two captures: the heading it turned and the distance it
//! drove along its arc, over consecutive, non-overlapping windows (independent noise), each
//! `span` s or a little more long.

/// One window of a robot's motion, between captures at `a` and `b` (s).
#[derive(Clone, Copy, Debug)]
pub struct Window {
    pub a: f64,
    pub b: f64,
    /// Heading turned, rad (counter-clockwise positive).
    pub turned: f64,
    /// Distance driven along the arc, m (negative backwards).
    pub driven: f64,
}

/// Windows of at least `span` s over `poses` (capture time, [x, y, heading]); a gap of more than
/// `max_gap` s between captures (a lost robot) starts a new window there instead of spanning it.
pub fn windows(poses: &[(f64, [f64; 3])], span: f64, max_gap: f64) -> Vec<Window> {
    let mut out = Vec::new();
    let mut start = 0;
    for k in 1..poses.len() {
        if poses[k].0 - poses[k - 1].0 > max_gap {
            start = k;
            continue;
        }
        if poses[k].0 - poses[start].0 >= span {
            out.push(window(poses[start], poses[k]));
            start = k;
        }
    }
    out
}

fn window((a, p): (f64, [f64; 3]), (b, q): (f64, [f64; 3])) -> Window {
    let turned = wrap(q[2] - p[2]);
    let mid = p[2] + 0.5 * turned;
    let (dx, dy) = (q[0] - p[0], q[1] - p[1]);
    // Along the mean heading: the chord of a circular arc; the arc is chord / sinc(turned / 2).
    let chord = dx * mid.cos() + dy * mid.sin();
    let half = 0.5 * turned;
    let sinc = if half.abs() < 1e-6 {
        1.0
    } else {
        half.sin() / half
    };
    Window {
        a,
        b,
        turned,
        driven: chord / sinc,
    }
}

/// An angle in `(-pi, pi]`.
pub fn wrap(a: f64) -> f64 {
    let t = std::f64::consts::TAU;
    let r = a.rem_euclid(t);
    if r > std::f64::consts::PI { r - t } else { r }
}
