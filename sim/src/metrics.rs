//! Measures of the paper's case studies: arrivals at end points (case I) and the summed leader-follower
//! distance S(t) of eq. (9) with its aggregation and dispersion phases (case II).
use glam::Vec2;
use serde::{Deserialize, Serialize};

/// Eq. (9): `S(t) = sum_i |P_i - P_1|` over the followers `i`, with `P_1` the leader's position, m.
pub fn sum_distance(leader: Vec2, followers: impl IntoIterator<Item = Vec2>) -> f32 {
    followers.into_iter().map(|p| p.distance(leader)).sum()
}

/// Eq. (9) on a slice of positions: the robot `leader` and the robots `followers` (indices into
/// `positions`).
pub fn sum_distance_of(positions: &[Vec2], leader: usize, followers: &[usize]) -> f32 {
    sum_distance(positions[leader], followers.iter().map(|&i| positions[i]))
}

/// The index of the first end point within `radius` of `pos` (the nearest if several are), if any.
pub fn arrival(pos: Vec2, end_points: &[Vec2], radius: f32) -> Option<usize> {
    end_points
        .iter()
        .enumerate()
        .map(|(k, p)| (k, p.distance(pos)))
        .filter(|&(_, d)| d <= radius)
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(k, _)| k)
}

/// How one trial of case I ended.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum TrialOutcome {
    /// Reached end point `point` (0-based index into the layout's end points) at `time` s.
    Arrived { point: usize, time: f32 },
    /// No end point before the time limit.
    TimedOut,
}

/// Arrival counts per end point (0-based) and the number of timeouts.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ArrivalCounts {
    pub per_point: Vec<usize>,
    pub timeouts: usize,
}

impl ArrivalCounts {
    /// Tallies `outcomes` over `points` end points.
    pub fn tally(outcomes: &[TrialOutcome], points: usize) -> Self {
        let mut c = ArrivalCounts {
            per_point: vec![0; points],
            timeouts: 0,
        };
        for o in outcomes {
            match *o {
                TrialOutcome::Arrived { point, .. } if point < points => c.per_point[point] += 1,
                _ => c.timeouts += 1,
            }
        }
        c
    }
    /// Trials that arrived somewhere.
    pub fn arrived(&self) -> usize {
        self.per_point.iter().sum()
    }
    /// Trials in all.
    pub fn trials(&self) -> usize {
        self.arrived() + self.timeouts
    }
    /// Arrivals at the given end points (0-based).
    pub fn at(&self, points: &[usize]) -> usize {
        points.iter().filter_map(|&k| self.per_point.get(k)).sum()
    }
    /// Number of end points with at least one arrival.
    pub fn distinct_points(&self) -> usize {
        self.per_point.iter().filter(|&&n| n > 0).count()
    }
    /// The largest arrival count at one end point.
    pub fn max_at_one_point(&self) -> usize {
        self.per_point.iter().copied().max().unwrap_or(0)
    }
}

/// What the swarm is doing in case II.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PhaseKind {
    /// No alarm: followers gather around the leader.
    Aggregation,
    /// Alarm pheromone sensed: the robots scatter.
    Dispersion,
}

/// A maximal time interval of one kind, `[start, end)` in seconds, with sample indices
/// `[first, last]` (inclusive).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Phase {
    pub kind: PhaseKind,
    pub start: f32,
    pub end: f32,
    pub first: usize,
    pub last: usize,
}

/// Splits a run into phases: sample `k` at `times[k]` is in a dispersion phase when `alarm[k]`.
/// A phase ends where the next one starts (the last ends at the last sample's time).
pub fn phases(times: &[f32], alarm: &[bool]) -> Vec<Phase> {
    let n = times.len().min(alarm.len());
    let mut out: Vec<Phase> = Vec::new();
    for k in 0..n {
        let kind = if alarm[k] {
            PhaseKind::Dispersion
        } else {
            PhaseKind::Aggregation
        };
        match out.last_mut() {
            Some(p) if p.kind == kind => {
                p.last = k;
                p.end = times[k];
            }
            _ => {
                if let Some(p) = out.last_mut() {
                    p.end = times[k];
                }
                out.push(Phase {
                    kind,
                    start: times[k],
                    end: times[k],
                    first: k,
                    last: k,
                });
            }
        }
    }
    out
}

/// Samples `first..=last` of `s` (clipped to its end) and the first of them, when there are some and
/// the first is positive.
fn positive_start(s: &[f32], first: usize, last: usize) -> Option<(&[f32], f32)> {
    let range = s.get(first..=last.min(s.len().saturating_sub(1)))?;
    let start = range.first().copied().unwrap_or(0.0);
    (!start.is_nan() && start > 0.0).then_some((range, start))
}

/// Relative fall of `s` over samples `first..=last`: `1 - min / s[first]` (0 for an empty range or a
/// zero start).
pub fn relative_fall(s: &[f32], first: usize, last: usize) -> f32 {
    let Some((range, start)) = positive_start(s, first, last) else {
        return 0.0;
    };
    let min = range.iter().copied().fold(f32::INFINITY, f32::min);
    1.0 - min / start
}

/// Relative rise of `s` over samples `first..=last`: `max / s[first] - 1` (0 for an empty range or a
/// zero start).
pub fn relative_rise(s: &[f32], first: usize, last: usize) -> f32 {
    let Some((range, start)) = positive_start(s, first, last) else {
        return 0.0;
    };
    let max = range.iter().copied().fold(f32::NEG_INFINITY, f32::max);
    max / start - 1.0
}
