//! Stepping a batch: each field's [`StepPlan`] (the CPU's) turned into passes over the whole batch.
use super::GpuGrids;
use super::record::{Kind, PlanEntry};
use crate::Result;
use colcos_sim::field::{Diffusion, GridSpec, StepPlan};
use rayon::prelude::*;

/// Fewest fields a thread takes when plans and entries are made side by side.
const PARALLEL_MIN: usize = 2048;

/// Passes under construction: their kinds, their entries (one per field, pass after pass), and the
/// slot each field's current values will be in after them.
struct Passes<'a> {
    kinds: Vec<Kind>,
    entries: &'a mut Vec<PlanEntry>,
    slots: Vec<u32>,
    coef_stride: usize,
}

impl Passes<'_> {
    /// Adds a pass of `kind` with an entry for each field `make` gives one (no pass if none does);
    /// the fields' entries are made side by side (a vector env's batch has tens of thousands).
    fn add(&mut self, kind: Kind, make: impl Fn(usize) -> Option<PlanEntry> + Sync) {
        let start = self.entries.len();
        let nf = self.slots.len();
        self.entries.resize(start + nf, PlanEntry::default());
        let stride = self.coef_stride;
        let any = (self.entries[start..].par_iter_mut())
            .zip(self.slots.par_iter_mut())
            .enumerate()
            .with_min_len(PARALLEL_MIN)
            .map(|(f, (entry, slot))| match make(f) {
                Some(mut e) => {
                    e.on = 1;
                    e.src = *slot;
                    e.coef = (f * stride) as u32;
                    if kind.flips() {
                        *slot ^= 1;
                    }
                    *entry = e;
                    true
                }
                None => false,
            })
            .reduce(|| false, |a, b| a || b);
        if any {
            self.kinds.push(kind);
        } else {
            self.entries.truncate(start);
        }
    }
}

/// Which passes the fields' plans need: the most explicit, one-sided and wind sub-steps of any
/// field, and whether any diffuses implicitly or uniformly.
#[derive(Default)]
struct Needs {
    explicit: usize,
    one_sided: usize,
    implicit: bool,
    uniform: bool,
    wind: usize,
}

impl Needs {
    fn add(&mut self, plan: &StepPlan) {
        match plan.diffusion {
            Diffusion::Explicit { substeps, .. } => self.explicit = self.explicit.max(substeps),
            Diffusion::OneSided { substeps, .. } => self.one_sided = self.one_sided.max(substeps),
            Diffusion::Implicit { .. } => self.implicit = true,
            Diffusion::Uniform => self.uniform = true,
            Diffusion::None => {}
        }
        if let Some(w) = plan.wind {
            self.wind = self.wind.max(w.substeps);
        }
    }
}

impl GpuGrids {
    /// Advances every field by `dt` seconds: exact evaporation and static injection, diffusion by the
    /// field's scheme, then wind; the same passes, in the same order, as
    /// [`GridField::step`](colcos_sim::field::GridField::step).
    pub fn step(&mut self, dt: f32) -> Result<()> {
        let ctx = self.ctx.clone();
        ctx.scoped("stepping the fields", || self.step_inner(dt))?
    }

    fn step_inner(&mut self, dt: f32) -> Result<()> {
        if self.fields.is_empty() {
            return Ok(());
        }
        let mut scratch = std::mem::take(&mut self.scratch);
        let result = self.plan_and_run(&mut scratch, dt);
        self.scratch = scratch;
        result
    }

    /// [`GpuGrids::step`] with `scratch`'s buffers.
    fn plan_and_run(&mut self, scratch: &mut super::Scratch, dt: f32) -> Result<()> {
        let spec = self.spec;
        let GridSpec { nx, ny, .. } = spec;
        let coef_stride = 2 * (nx + ny);
        // Each field's plan (two f64 transcendentals: side by side for a vector env's batch).
        let plans = &mut scratch.plans;
        plans.clear();
        plans.par_extend(
            (self.fields.par_iter_mut())
                .with_min_len(PARALLEL_MIN)
                .map(|st| StepPlan::new(&spec, &st.params, dt, &mut st.decay_carry)),
        );
        // No plan is the same for every field: `dt` not positive or an empty grid.
        if plans.iter().any(Option::is_none) {
            return Ok(());
        }
        let plans: Vec<&StepPlan> = plans.iter().flatten().collect();
        // The passes some field needs (a pass no field needs is not tried), and the Thomas
        // coefficients of implicit fields whose diffusion number changed.
        let mut needs = Needs::default();
        for (fi, (st, plan)) in self.fields.iter_mut().zip(&plans).enumerate() {
            needs.add(plan);
            if let Diffusion::Implicit { r } = plan.diffusion
                && st.coef_r != Some(r.to_bits())
            {
                let (mx, cx) = colcos_sim::field::thomas_coefficients(nx, r);
                let (my, cy) = colcos_sim::field::thomas_coefficients(ny, r);
                let c: Vec<f32> = [mx, cx, my, cy].concat();
                self.ctx.queue.write_buffer(
                    &self.coef,
                    (fi * coef_stride) as u64 * 4,
                    bytemuck::cast_slice(&c),
                );
                st.coef_r = Some(r.to_bits());
            }
        }

        let fields = &self.fields;
        let inj = |f: usize| fields[f].inj_offset.map_or(-1, |o| o as i32);
        scratch.entries.clear();
        let mut passes = Passes {
            kinds: Vec::new(),
            entries: &mut scratch.entries,
            slots: self.fields.iter().map(|s| s.slot).collect(),
            coef_stride,
        };
        passes.add(Kind::Evaporate, |f| {
            let p = &plans[f];
            // Without a map and with a = 1 the CPU leaves the values as they are (no flush either).
            (!p.diffusion.fuses_decay() && (inj(f) >= 0 || p.a != 1.0)).then_some(PlanEntry {
                inj: inj(f),
                a: p.a,
                b: p.b,
                ..Default::default()
            })
        });
        for k in 0..needs.explicit {
            passes.add(Kind::Explicit, |f| match plans[f].diffusion {
                Diffusion::Explicit { substeps, r } if k < substeps => {
                    let (a, b, i) = if k == 0 {
                        (plans[f].a, plans[f].b, inj(f))
                    } else {
                        (1.0, 0.0, -1)
                    };
                    Some(PlanEntry {
                        inj: i,
                        a,
                        b,
                        r,
                        ..Default::default()
                    })
                }
                _ => None,
            });
        }
        for k in 0..needs.one_sided {
            passes.add(Kind::OneSided, |f| match plans[f].diffusion {
                Diffusion::OneSided { substeps, s } if k < substeps => Some(PlanEntry {
                    inj: -1,
                    r: s,
                    ..Default::default()
                }),
                _ => None,
            });
        }
        if needs.implicit {
            passes.add(Kind::XSolve, |f| match plans[f].diffusion {
                Diffusion::Implicit { r } => Some(PlanEntry {
                    inj: inj(f),
                    a: plans[f].a,
                    b: plans[f].b,
                    r,
                    ..Default::default()
                }),
                _ => None,
            });
        }
        if needs.implicit && ny > 1 {
            passes.add(Kind::YSolve, |f| match plans[f].diffusion {
                Diffusion::Implicit { r } => Some(PlanEntry {
                    inj: -1,
                    r,
                    ..Default::default()
                }),
                _ => None,
            });
        }
        if needs.uniform {
            // Infinite diffusion (uniform at the mean): finish the passes so far, average on the CPU.
            self.run_passes(&std::mem::take(&mut passes.kinds), passes.entries);
            passes.entries.clear();
            for (f, p) in plans.iter().enumerate() {
                if p.diffusion == Diffusion::Uniform {
                    self.fields[f].slot = passes.slots[f];
                    let v = self.read_field(f)?;
                    let mean = (v.iter().map(|&v| v as f64).sum::<f64>() / v.len() as f64) as f32;
                    self.write_field(f, &vec![mean; v.len()])?;
                }
            }
        }
        for k in 0..needs.wind {
            passes.add(Kind::AdvectX, |f| {
                let w = plans[f].wind.filter(|w| k < w.substeps)?;
                w.x(&spec).map(|c| PlanEntry {
                    inj: -1,
                    c,
                    ..Default::default()
                })
            });
            passes.add(Kind::AdvectY, |f| {
                let w = plans[f].wind.filter(|w| k < w.substeps)?;
                w.y(&spec).map(|c| PlanEntry {
                    inj: -1,
                    c,
                    ..Default::default()
                })
            });
        }
        self.run_passes(&passes.kinds, passes.entries);
        for (st, s) in self.fields.iter_mut().zip(passes.slots) {
            st.slot = s;
        }
        Ok(())
    }
}
