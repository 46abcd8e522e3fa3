//! The state of the metrics during one run: fed every step and at every sample time, reduced at the
//! end into one value per column.
use super::geometry::{clusters, contacts, mean_nearest_neighbour};
use super::{Metric, MetricSet, Signal};
use colcos_sim::field::{FieldModel, GridSpec};
use colcos_sim::metrics::{arrival, sum_distance_of};
use colcos_sim::world::World;
use glam::Vec2;

/// One run's metrics in progress.
pub struct Recorder<'a> {
    set: &'a MetricSet,
    leader: Option<usize>,
    followers: Vec<usize>,
    sample_every: u64,
    positions: Vec<Vec2>,
    times: Vec<f64>,
    s: Vec<f64>,
    nn: Vec<Option<f64>>,
    /// First sample time each threshold was met.
    crossed: Vec<Option<f64>>,
    covered: Vec<bool>,
    coverage_nx: usize,
    contact_reach: f32,
    contacts_now: Vec<(u32, u32)>,
    contacts_before: Vec<(u32, u32)>,
    collisions: u64,
    arrived: Vec<Option<usize>>,
    needs_arrivals: bool,
    needs_contacts: bool,
}

impl<'a> Recorder<'a> {
    /// A recorder for `world` (already built, at t = 0).
    pub fn new(set: &'a MetricSet, world: &World) -> Recorder<'a> {
        let n = world.robot_count();
        let o = &set.options;
        let leader = (0..n).find(|&i| world.role(i) == o.leader_role);
        let followers = (0..n)
            .filter(|&i| world.role(i) == o.follower_role)
            .collect();
        let arena = world.arena();
        let coverage_nx = ((arena.x / o.coverage_cell).ceil() as usize).max(1);
        let coverage_ny = ((arena.y / o.coverage_cell).ceil() as usize).max(1);
        let needs_arrivals = set.metrics.iter().any(|m| {
            matches!(
                m,
                Metric::Arrivals | Metric::ArrivalsFood | Metric::Timeouts
            )
        });
        let mut r = Recorder {
            set,
            leader,
            followers,
            sample_every: ((o.sample_every / world.dt()).round() as u64).max(1),
            positions: Vec::with_capacity(n),
            times: Vec::new(),
            s: Vec::new(),
            nn: Vec::new(),
            crossed: vec![None; set.thresholds.len()],
            covered: vec![false; coverage_nx * coverage_ny],
            coverage_nx,
            contact_reach: 2.0 * world.robot_params().radius + o.contact_margin,
            contacts_now: Vec::new(),
            contacts_before: Vec::new(),
            collisions: 0,
            arrived: vec![None; n],
            needs_arrivals,
            needs_contacts: set.has(Metric::Collisions),
        };
        r.positions_of(world);
        if r.needs_contacts {
            contacts(&r.positions, r.contact_reach, &mut r.contacts_before);
        }
        r.per_step();
        r.sample(world);
        r
    }

    fn positions_of(&mut self, world: &World) {
        self.positions.clear();
        self.positions.extend(world.poses().iter().map(|p| p.pos));
    }

    /// After every step.
    pub fn after_step(&mut self, world: &World) {
        self.positions_of(world);
        if self.needs_contacts {
            contacts(&self.positions, self.contact_reach, &mut self.contacts_now);
            self.collisions += self
                .contacts_now
                .iter()
                .filter(|c| self.contacts_before.binary_search(c).is_err())
                .count() as u64;
            std::mem::swap(&mut self.contacts_now, &mut self.contacts_before);
        }
        self.per_step();
        if world.tick().is_multiple_of(self.sample_every) {
            self.sample(world);
        }
    }

    /// Every robot that can arrive has: the run may end early (`end_on_arrival`).
    pub fn all_arrived(&self) -> bool {
        self.needs_arrivals && self.arrived.iter().all(Option::is_some)
    }

    fn per_step(&mut self) {
        let o = &self.set.options;
        for p in &self.positions {
            let cx = ((p.x / o.coverage_cell).max(0.0) as usize).min(self.coverage_nx - 1);
            let cy = (p.y / o.coverage_cell).max(0.0) as usize;
            if let Some(c) = self.covered.get_mut(cy * self.coverage_nx + cx) {
                *c = true;
            }
        }
        if self.needs_arrivals {
            let points: Vec<Vec2> = o
                .arrival_points
                .iter()
                .map(|p| Vec2::new(p[0], p[1]))
                .collect();
            for (a, p) in self.arrived.iter_mut().zip(&self.positions) {
                if a.is_none() {
                    *a = arrival(*p, &points, o.arrival_radius);
                }
            }
        }
    }

    fn sample(&mut self, world: &World) {
        // The tick count times dt as written (0.02, not its f32), so that times read 5.4, not 5.399...
        let t = crate::axis::round_generated(world.tick() as f64 * widen(world.dt()));
        self.times.push(t);
        if let Some(l) = self.leader {
            self.s
                .push(widen(sum_distance_of(&self.positions, l, &self.followers)));
        }
        let wants_nn = self.set.has(Metric::NnDistance)
            || self.set.has(Metric::NnDistanceFinal)
            || self
                .set
                .thresholds
                .iter()
                .any(|t| t.signal == Signal::NnDistance);
        self.nn.push(if wants_nn {
            mean_nearest_neighbour(&self.positions)
        } else {
            None
        });
        for k in 0..self.set.thresholds.len() {
            if self.crossed[k].is_some() {
                continue;
            }
            let th = &self.set.thresholds[k];
            let value = match th.signal {
                Signal::S => self.s.last().copied(),
                Signal::NnDistance => self.nn.last().copied().flatten(),
                Signal::Clusters => {
                    Some(clusters(&self.positions, self.set.options.cluster_distance) as f64)
                }
                Signal::AreaCovered => Some(self.area_covered()),
                Signal::FieldMass(p) => Some(field_mass(world, p)),
            };
            if let Some(v) = value
                && (if th.below {
                    v <= th.value
                } else {
                    v >= th.value
                })
            {
                self.crossed[k] = Some(t);
            }
        }
    }

    fn area_covered(&self) -> f64 {
        self.covered.iter().filter(|&&c| c).count() as f64 / self.covered.len() as f64
    }

    /// One value per column of the metric set (`None`: an empty cell).
    pub fn finish(mut self, world: &World) -> Vec<Option<f64>> {
        self.positions_of(world);
        let o = &self.set.options;
        let mut out = Vec::with_capacity(self.set.columns.len());
        let food: Vec<usize> = o.food_points.iter().map(|f| f - 1).collect();
        for m in &self.set.metrics {
            match m {
                Metric::SMean => out.push(mean(&self.s)),
                Metric::SFinal => out.push(self.s.last().copied()),
                Metric::SHalveTime => out.push(self.s.first().and_then(|&s0| {
                    (s0 > 0.0)
                        .then(|| {
                            self.s
                                .iter()
                                .zip(&self.times)
                                .find(|(s, _)| **s <= s0 / 2.0)
                        })
                        .flatten()
                        .map(|(_, t)| *t)
                })),
                Metric::Arrivals => out.push(Some(self.arrived.iter().flatten().count() as f64)),
                Metric::ArrivalsFood => out.push(Some(
                    self.arrived
                        .iter()
                        .flatten()
                        .filter(|k| food.contains(k))
                        .count() as f64,
                )),
                Metric::Timeouts => out.push(Some(
                    self.arrived.iter().filter(|a| a.is_none()).count() as f64,
                )),
                Metric::NnDistance => {
                    let v: Vec<f64> = self.nn.iter().flatten().copied().collect();
                    out.push(mean(&v))
                }
                Metric::NnDistanceFinal => out.push(mean_nearest_neighbour(&self.positions)),
                Metric::Clusters => {
                    out.push(Some(clusters(&self.positions, o.cluster_distance) as f64))
                }
                Metric::AreaCovered => out.push(Some(self.area_covered())),
                Metric::Collisions => out.push(Some(self.collisions as f64)),
                Metric::FieldMass => {
                    out.extend((0..self.set.pheromones.len()).map(|p| Some(field_mass(world, p))))
                }
                Metric::TimeToThreshold => out.extend(self.crossed.iter().copied()),
            }
        }
        out
    }
}

/// An f32 as the f64 it reads as (`5.4f32` -> `5.4`, not `5.400000095367432`): the table shows the
/// simulator's own figure, not the binary noise of widening it.
pub fn widen(x: f32) -> f64 {
    x.to_string().parse().unwrap_or(x as f64)
}

fn mean(v: &[f64]) -> Option<f64> {
    (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64)
}

/// Sum of `Phi h^2` over the field grid: a grid pheromone's cells, a Gaussian one evaluated at the
/// centres of the scenario's field grid.
pub fn field_mass(world: &World, index: usize) -> f64 {
    let Some(p) = world.pheromones().get(index) else {
        return f64::NAN;
    };
    match &p.model {
        FieldModel::Grid(g) => {
            let h = g.spec().cell as f64;
            g.values().iter().map(|&v| v as f64).sum::<f64>() * h * h
        }
        FieldModel::Gaussian(g) => {
            let spec = GridSpec::covering(world.arena(), world.scenario().spec.field.cell);
            let h = spec.cell as f64;
            let mut total = 0.0f64;
            for j in 0..spec.ny {
                for i in 0..spec.nx {
                    let c = Vec2::new((i as f32 + 0.5) * spec.cell, (j as f32 + 0.5) * spec.cell);
                    total += g.value_at(c) as f64;
                }
            }
            total * h * h
        }
    }
}
