//! The disc solver: move, then Gauss-Seidel passes that separate overlapping equal discs.
use super::Step;
use crate::robot::Pose;
use crate::sensors::NeighbourIndex;
use glam::Vec2;

/// Most separation passes of the disc solver per step (it stops once no pair overlaps by more than
/// [`DISC_TOLERANCE`]; in free space one pass, in a pile pushed into a wall a few dozen).
const DISC_MAX_PASSES: usize = 64;
/// Overlap the disc solver leaves alone, m.
const DISC_TOLERANCE: f32 = 2e-4;

#[derive(Default)]
pub(super) struct DiscState {
    index: NeighbourIndex,
    positions: Vec<Vec2>,
    /// Robots to visit in this pass, and those to visit in the next.
    active: Vec<u32>,
    next: Vec<u32>,
    /// Last pass in which each robot was queued for the next.
    stamp: Vec<u32>,
}

impl DiscState {
    pub(super) fn step(
        &mut self,
        poses: &mut [Pose],
        velocity: impl Fn(usize) -> (f32, f32),
        facing: impl Fn(usize, f32) -> Vec2,
        step: Step,
        size: Vec2,
    ) {
        let Step { dt, lo, hi, radius } = step;
        // Move: along the heading at the start of the step (as rapier does), then turn.
        self.positions.clear();
        for (i, pose) in poses.iter_mut().enumerate() {
            let (forward, yaw) = velocity(i);
            let p = (pose.pos + facing(i, pose.heading) * (forward * dt)).clamp(lo, hi);
            pose.heading = wrap_angle(pose.heading + yaw * dt);
            self.positions.push(p);
        }
        // Separate: Gauss-Seidel passes over overlapping pairs, in index order (deterministic). The
        // grid is built once per step; the slack covers the small moves of the passes.
        let contact = 2.0 * radius;
        let slack = 0.5 * radius;
        self.index.rebuild(size, contact + slack, &self.positions);
        let reach = contact + slack;
        // The first pass visits every robot; later passes only those touched by an overlap in the
        // pass before, so a pile somewhere costs only its own robots.
        let n = self.positions.len();
        self.active.clear();
        self.active.extend(0..n as u32);
        self.stamp.clear();
        self.stamp.resize(n, u32::MAX);
        for pass in 0..DISC_MAX_PASSES {
            let mut worst = 0.0f32;
            self.next.clear();
            for k in 0..self.active.len() {
                // Alternate the sweep direction: pushes travel down a line of robots both ways.
                let i = if pass % 2 == 0 {
                    self.active[k]
                } else {
                    self.active[self.active.len() - 1 - k]
                } as usize;
                let positions = &mut self.positions;
                let (stamp, next) = (&mut self.stamp, &mut self.next);
                self.index.for_each_near(positions[i], reach, |j| {
                    if j == i {
                        return;
                    }
                    let d = positions[j] - positions[i];
                    let dist2 = d.length_squared();
                    if dist2 >= contact * contact {
                        return;
                    }
                    let dist = dist2.sqrt();
                    worst = worst.max(contact - dist);
                    // Coincident centres: split along a direction fixed by the indices.
                    let (a, b) = (i.min(j), i.max(j));
                    let n = if dist > 1e-9 {
                        d / dist
                    } else {
                        let u = Vec2::from_angle(a as f32 * 2.399_963 + b as f32);
                        if i == a { u } else { -u }
                    };
                    let push = 0.5 * (contact - dist) * n;
                    positions[i] = (positions[i] - push).clamp(lo, hi);
                    positions[j] = (positions[j] + push).clamp(lo, hi);
                    for m in [i, j] {
                        if stamp[m] != pass as u32 {
                            stamp[m] = pass as u32;
                            next.push(m as u32);
                        }
                    }
                });
            }
            if worst <= DISC_TOLERANCE {
                break;
            }
            // Index order keeps the sweeps deterministic and cache-friendly.
            self.next.sort_unstable();
            std::mem::swap(&mut self.active, &mut self.next);
        }
        for (pose, &p) in poses.iter_mut().zip(&self.positions) {
            pose.pos = p;
        }
    }
}

/// Angle in (-pi, pi], as rapier reports headings.
fn wrap_angle(a: f32) -> f32 {
    use std::f32::consts::{PI, TAU};
    if !a.is_finite() {
        return 0.0;
    }
    let w = crate::angle::rem_tau(a + PI) - PI;
    if w <= -PI { w + TAU } else { w }
}
