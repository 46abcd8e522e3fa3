//! Injection: robots lay trails on grid pheromones along their path and move their Gaussian sources,
//! at their tracked poses (as the real host does) or their true ones.
use super::World;
use crate::field::{FieldModel, GridBand, Kernel};
use crate::robot::Pose;
use crate::scenario::InjectAt;
use crate::tracker::TrackedPose;
use glam::Vec2;
use rayon::prelude::*;

/// From this many trail deposits a step, fields take their deposits in parallel.
const PARALLEL_DEPOSITS: usize = 256;
/// Bands of rows each grid field is cut into when deposits run in parallel.
const BANDS: usize = 4;

/// One robot's trail deposit of this step: the segment from where it injected last to where it is.
pub(super) struct Segment {
    pheromone: usize,
    kernel: Kernel,
    from: Vec2,
    to: Vec2,
    amount: f32,
}

/// Where the host believes robot `i` is (see [`World::injection_point`]).
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

impl World {
    /// Where the host believes robot `i` is, or `None` if the tracker has not seen it yet.
    pub fn injection_point(&self, i: usize) -> Option<Vec2> {
        injection_point_of(self.inject_at, self.physics.poses(), &self.tracked, i)
    }

    pub(super) fn inject(&mut self) {
        let dt = self.dt;
        // This step's trail segments, in scenario order.
        self.segments.clear();
        for dep in &self.deposits {
            let robot = dep.robot;
            let Some(to) =
                injection_point_of(self.inject_at, self.physics.poses(), &self.tracked, robot)
            else {
                continue;
            };
            self.segments.push(Segment {
                pheromone: dep.pheromone,
                kernel: dep.kernel,
                from: self.last_injection[robot].unwrap_or(to),
                to,
                amount: dep.rate * dt,
            });
        }
        // A cell's value depends on the order of its own deposits only: each field, cut into bands
        // of rows, takes its segments in scenario order in every band, and bands run in parallel.
        let segments = &self.segments;
        let deposit_into = |index: usize, band: &mut GridBand| {
            for s in segments.iter().filter(|s| s.pheromone == index) {
                band.deposit_segment(&s.kernel, s.from, s.to, s.amount);
            }
        };
        if self.deposits.len() >= PARALLEL_DEPOSITS {
            let mut bands: Vec<(usize, GridBand)> = Vec::new();
            for (index, ph) in self.pheromones.iter_mut().enumerate() {
                if let FieldModel::Grid(grid) = &mut ph.model {
                    let rows = grid.spec().ny.div_ceil(BANDS).max(1);
                    bands.extend(grid.bands_mut(rows).map(|band| (index, band)));
                }
            }
            bands
                .par_iter_mut()
                .for_each(|(index, band)| deposit_into(*index, band));
        } else {
            // A small world (a batched environment's): the whole grid as one band, nothing allocated.
            for (index, ph) in self.pheromones.iter_mut().enumerate() {
                if let FieldModel::Grid(grid) = &mut ph.model {
                    let ny = grid.spec().ny;
                    deposit_into(index, &mut grid.band_mut(0, ny));
                }
            }
        }
        for i in 0..self.robots.len() {
            if let Some(p) = self.injection_point(i) {
                self.last_injection[i] = Some(p);
            }
        }
        for e in 0..self.emitters.len() {
            let Some(pos) = self.injection_point(self.emitters[e].robot) else {
                continue;
            };
            let refresh = match &self.emitters[e].near {
                None => true,
                Some((targets, distance)) => targets.iter().any(|&t| {
                    self.injection_point(t)
                        .is_some_and(|q| q.distance(pos) <= *distance)
                }),
            };
            if refresh {
                let (pheromone, source) = (self.emitters[e].pheromone, self.emitters[e].source);
                if let FieldModel::Gaussian(g) = &mut self.pheromones[pheromone].model {
                    g.sources[source].centre = pos;
                    // The field's own clock, not the world's: the two are summed differently in f32,
                    // and a start a hair in the future would read as "not yet emitted".
                    g.sources[source].start = g.time;
                }
            }
        }
    }
}
