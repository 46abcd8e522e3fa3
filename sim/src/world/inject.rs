//! Injection: the rules by which robots lay trails on grid pheromones along their path and move their
//! Gaussian sources, at their tracked poses (as the real host does) or their true ones. Stage `inject`.
use super::FieldSet;
use crate::field::{FieldModel, GridSpec, Kernel, Pheromone};
use crate::robot::Pose;
use crate::scenario::InjectAt;
use crate::tracker::TrackedPose;
use glam::Vec2;
use rayon::prelude::*;

/// From this many trail deposits a step, fields take their deposits in parallel (one task per field).
const PARALLEL_DEPOSITS: usize = 64;
/// From this many, each grid field is also cut into bands of rows that take their deposits in parallel.
const BANDED_DEPOSITS: usize = 256;
/// Bands of rows each grid field is cut into then.
const BANDS: usize = 4;

/// An emitter switched by action is on from this fraction.
pub const EMIT_ON: f32 = 0.5;

/// One robot's trail deposit of this step: the segment from where it injected last to where it is,
/// `amount * kernel(distance to the segment)` added to grid pheromone `pheromone`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TrailSegment {
    pub pheromone: usize,
    pub kernel: Kernel,
    pub from: Vec2,
    pub to: Vec2,
    pub amount: f32,
}

/// Where the host believes robot `i` is: its true pose, or its tracked one once the tracker has seen it.
fn injection_point_of(
    inject_at: InjectAt,
    poses: &[Pose],
    tracked: &[TrackedPose],
    i: usize,
) -> Option<Vec2> {
    match inject_at {
        InjectAt::True => Some(poses[i].pos),
        InjectAt::Tracked => tracked[i].seen.then_some(tracked[i].pose.pos),
    }
}

/// The first and last of `count` bands of `rows` rows that segment `s` may reach: its bounding box
/// grown by the kernel's support and a cell (the margin [`GridBand::deposit_segment`] skips by, so no
/// band it would deposit into is left out). `None` for a segment that deposits nothing.
fn bands_reached(
    s: &TrailSegment,
    spec: &GridSpec,
    rows: usize,
    count: usize,
) -> Option<(usize, usize)> {
    let support = s.kernel.support();
    if support.is_nan() || support < 0.0 || !s.from.is_finite() || !s.to.is_finite() {
        return None;
    }
    let reach = support + spec.cell;
    let row = |y: f32| ((y / spec.cell) as usize / rows).min(count - 1);
    let lo = row(s.from.y.min(s.to.y) - reach);
    let hi = row(s.from.y.max(s.to.y) + reach);
    Some((lo, hi))
}

/// A trail deposit rule of one robot.
pub(super) struct Deposit {
    pub robot: usize,
    pub pheromone: usize,
    pub kernel: Kernel,
    /// Units per second at the kernel's peak (for an agent's action: at a fraction of 1).
    pub rate: f32,
    /// `Some(k)`: the robot's deposit action `k`, laid at the fraction its agent chose.
    pub action: Option<usize>,
}

/// A Gaussian source attached to one robot.
pub(super) struct Emitter {
    pub robot: usize,
    pub pheromone: usize,
    /// Index of the source in the pheromone's [`crate::field::GaussianField`].
    pub source: usize,
    pub rule: EmitRule,
}

/// When an emitter's source is refreshed at its robot.
pub(super) enum EmitRule {
    /// Every step.
    Follow,
    /// While the robot is within the distance of one of the target robots.
    Near(Vec<usize>, f32),
    /// While the robot's action `k` (among its deposit actions) is at least 0.5.
    Action(usize),
}

pub struct Injection {
    inject_at: InjectAt,
    deposits: Vec<Deposit>,
    emitters: Vec<Emitter>,
    /// Where each robot injected last (None before its first tracked pose).
    last_injection: Vec<Option<Vec2>>,
    /// Each robot's deposit actions' fractions for the next step (`[robot][action]`, flat; robot
    /// `i`'s from `action_first[i]`), 0 until an agent chooses.
    action_rates: Vec<f32>,
    action_first: Vec<usize>,
    /// Scratch: this step's trail segments.
    segments: Vec<TrailSegment>,
    /// Scratch: for each band of rows of each grid field (in field order), the indices of the segments
    /// that may reach it.
    band_segments: Vec<Vec<u32>>,
    /// Scratch: for each pheromone, its first list in `band_segments` and how many it has.
    band_lists: Vec<(usize, usize)>,
}

impl Injection {
    pub(super) fn new(
        inject_at: InjectAt,
        deposits: Vec<Deposit>,
        emitters: Vec<Emitter>,
        robots: usize,
    ) -> Self {
        let mut action_first = vec![0; robots + 1];
        for d in deposits.iter().filter(|d| d.action.is_some()) {
            action_first[d.robot + 1] += 1;
        }
        for e in &emitters {
            if let EmitRule::Action(_) = e.rule {
                action_first[e.robot + 1] += 1;
            }
        }
        for i in 0..robots {
            action_first[i + 1] += action_first[i];
        }
        Injection {
            inject_at,
            action_rates: vec![0.0; action_first[robots]],
            action_first,
            deposits,
            emitters,
            last_injection: vec![None; robots],
            segments: Vec::new(),
            band_segments: Vec::new(),
            band_lists: Vec::new(),
        }
    }

    /// Robot `i`'s deposit actions' fractions of their `max_rate` for the next steps.
    pub fn deposit_actions(&self, i: usize) -> &[f32] {
        &self.action_rates[self.action_first[i]..self.action_first[i + 1]]
    }

    /// Sets robot `i`'s deposit actions (fractions of `max_rate`, clamped to `[0, 1]`; a non-finite
    /// one lays nothing); extra entries are ignored, missing ones keep their value.
    pub fn set_deposit_actions(&mut self, i: usize, fractions: impl IntoIterator<Item = f32>) {
        let range = self.action_first[i]..self.action_first[i + 1];
        for (out, f) in self.action_rates[range].iter_mut().zip(fractions) {
            *out = if f.is_finite() {
                f.clamp(0.0, 1.0)
            } else {
                0.0
            };
        }
    }

    /// The trail segments of the last step, in scenario order (deposited already unless the grid
    /// pheromones are stepped outside the world, see [`FieldSet::set_external_grids`]).
    pub fn segments(&self) -> &[TrailSegment] {
        &self.segments
    }

    /// Where the host believes robot `i` is, or `None` if the tracker has not seen it yet.
    pub fn point(&self, poses: &[Pose], tracked: &[TrackedPose], i: usize) -> Option<Vec2> {
        injection_point_of(self.inject_at, poses, tracked, i)
    }
}

/// Stage `inject`: every robot's trail deposits of this step (the segment from where it injected last
/// to where the host believes it is now) and its Gaussian sources moved or refreshed there.
///
/// Grid pheromones stepped outside the world ([`FieldSet::set_external_grids`]) take no deposits here:
/// the segments stay in [`Injection::segments`] for their owner.
///
/// Reads `poses` (true) and `tracked`; writes the grid pheromones' values, the Gaussian sources'
/// centres and start times, and where each robot injected last.
pub fn inject(
    injection: &mut Injection,
    fields: &mut FieldSet,
    poses: &[Pose],
    tracked: &[TrackedPose],
    dt: f32,
) {
    let inject_at = injection.inject_at;
    let point = |i: usize| injection_point_of(inject_at, poses, tracked, i);
    // This step's trail segments, in scenario order.
    injection.segments.clear();
    for dep in &injection.deposits {
        let robot = dep.robot;
        let Some(to) = point(robot) else {
            continue;
        };
        let rate = match dep.action {
            None => dep.rate,
            Some(k) => match injection.action_rates[injection.action_first[robot] + k] {
                0.0 => continue,
                f => dep.rate * f,
            },
        };
        injection.segments.push(TrailSegment {
            pheromone: dep.pheromone,
            kernel: dep.kernel,
            from: injection.last_injection[robot].unwrap_or(to),
            to,
            amount: rate * dt,
        });
    }
    if !fields.external_grids() {
        deposit_segments(injection, fields.pheromones_mut());
    }
    for (i, last) in injection.last_injection.iter_mut().enumerate() {
        if let Some(p) = point(i) {
            *last = Some(p);
        }
    }
    for e in &injection.emitters {
        let Some(pos) = point(e.robot) else {
            continue;
        };
        let refresh = match &e.rule {
            EmitRule::Follow => true,
            EmitRule::Near(targets, distance) => targets
                .iter()
                .any(|&t| point(t).is_some_and(|q| q.distance(pos) <= *distance)),
            EmitRule::Action(k) => {
                injection.action_rates[injection.action_first[e.robot] + k] >= EMIT_ON
            }
        };
        if refresh && let FieldModel::Gaussian(g) = &mut fields.pheromones_mut()[e.pheromone].model
        {
            g.sources[e.source].centre = pos;
            // The field's own clock, not the world's: the two are summed differently in f32, and a
            // start a hair in the future would read as "not yet emitted".
            g.sources[e.source].start = g.time;
        }
    }
}

/// This step's segments deposited into the grid pheromones. A cell's value depends on the order of its
/// own deposits only: each field is cut into bands of rows, every band takes the segments that may
/// reach it in scenario order, and bands run in parallel.
fn deposit_segments(injection: &mut Injection, pheromones: &mut [Pheromone]) {
    let segments = &injection.segments;
    let deposits = injection.deposits.len();
    if deposits >= PARALLEL_DEPOSITS {
        let bands_per_field = if deposits >= BANDED_DEPOSITS {
            BANDS
        } else {
            1
        };
        let band_rows = |spec: &GridSpec| spec.ny.div_ceil(bands_per_field).max(1);
        // First the lists of segments per band (reading the grids' geometry only) ...
        let lists = &mut injection.band_segments;
        lists.iter_mut().for_each(Vec::clear);
        injection.band_lists.clear();
        injection.band_lists.resize(pheromones.len(), (0, 0));
        let mut first_list = 0;
        for (index, ph) in pheromones.iter().enumerate() {
            if let FieldModel::Grid(grid) = &ph.model {
                let spec = *grid.spec();
                let rows = band_rows(&spec);
                let count = spec.ny.div_ceil(rows).max(1);
                injection.band_lists[index] = (first_list, count);
                if lists.len() < first_list + count {
                    lists.resize_with(first_list + count, Vec::new);
                }
                for (k, s) in segments.iter().enumerate() {
                    if s.pheromone == index
                        && let Some((lo, hi)) = bands_reached(s, &spec, rows, count)
                    {
                        for list in &mut lists[first_list + lo..=first_list + hi] {
                            list.push(k as u32);
                        }
                    }
                }
                first_list += count;
            }
        }
        // ... then the bands themselves, each with its list (iterators only: nothing allocated).
        let lists = &injection.band_segments;
        pheromones
            .par_iter_mut()
            .zip(injection.band_lists.par_iter())
            .for_each(|(ph, &(first, count))| {
                if let FieldModel::Grid(grid) = &mut ph.model {
                    let rows = band_rows(grid.spec());
                    grid.par_bands_mut(rows)
                        .zip(lists[first..first + count].par_iter())
                        .for_each(|(mut band, list)| {
                            for &k in list {
                                let s = &segments[k as usize];
                                band.deposit_segment(&s.kernel, s.from, s.to, s.amount);
                            }
                        });
                }
            });
    } else {
        // A small world (a batched environment's): the whole grid as one band, nothing allocated.
        for (index, ph) in pheromones.iter_mut().enumerate() {
            if let FieldModel::Grid(grid) = &mut ph.model {
                let ny = grid.spec().ny;
                let mut band = grid.band_mut(0, ny);
                for s in segments.iter().filter(|s| s.pheromone == index) {
                    band.deposit_segment(&s.kernel, s.from, s.to, s.amount);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::field::{GridField, GridParams, test_segments};

    proptest::proptest! {
        /// Every band that a segment's deposit changes is among the bands it is listed for.
        #[test]
        fn a_segment_is_listed_for_every_band_it_reaches(
            (kernel, spec, from, to) in test_segments(),
            bands in 1usize..9,
        ) {
            let rows = spec.ny.div_ceil(bands).max(1);
            let count = spec.ny.div_ceil(rows).max(1);
            let s = TrailSegment { pheromone: 0, kernel, from, to, amount: 1.0 };
            let (lo, hi) = bands_reached(&s, &spec, rows, count).expect("a finite segment");
            let mut g = GridField::new(spec, GridParams::default());
            for mut band in g.bands_mut(rows) {
                band.deposit_segment(&s.kernel, s.from, s.to, s.amount);
            }
            for (j, row) in g.values().chunks(spec.nx).enumerate() {
                if row.iter().any(|&v| v != 0.0) {
                    let band = j / rows;
                    proptest::prop_assert!(
                        (lo..=hi).contains(&band),
                        "row {j} (band {band}) got a deposit, listed bands {lo}..={hi}"
                    );
                }
            }
        }
    }
}
