//! Injection: robots lay trails on grid pheromones along their path and move their Gaussian sources,
//! at their tracked poses (as the real host does) or their true ones.
use super::World;
use crate::field::FieldModel;
use crate::scenario::InjectAt;
use glam::Vec2;

impl World {
    /// Where the host believes robot `i` is, or `None` if the tracker has not seen it yet.
    pub fn injection_point(&self, i: usize) -> Option<Vec2> {
        match self.inject_at {
            InjectAt::True => Some(self.physics.poses()[i].pos),
            InjectAt::Tracked => self.tracked[i].seen.then_some(self.tracked[i].pose.pos),
        }
    }

    pub(super) fn inject(&mut self) {
        let dt = self.dt;
        for d in 0..self.deposits.len() {
            let (robot, pheromone, kernel, rate) = {
                let dep = &self.deposits[d];
                (dep.robot, dep.pheromone, dep.kernel, dep.rate)
            };
            let Some(to) = self.injection_point(robot) else {
                continue;
            };
            let from = self.last_injection[robot].unwrap_or(to);
            if let FieldModel::Grid(grid) = &mut self.pheromones[pheromone].model {
                grid.deposit_segment(&kernel, from, to, rate * dt);
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
