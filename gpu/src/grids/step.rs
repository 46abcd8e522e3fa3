//! Stepping a batch: each field's [`StepPlan`] (the CPU's) turned into passes over the whole batch.
use super::GpuGrids;
use super::record::{Kind, PlanEntry};
use crate::Result;
use colcos_sim::field::{Diffusion, GridSpec, StepPlan};
use rayon::prelude::*;

/// Passes under construction, and the slot each field's current values will be in after them.
struct Passes {
    list: Vec<(Kind, Vec<PlanEntry>)>,
    slots: Vec<u32>,
    coef_stride: usize,
}

impl Passes {
    /// Adds a pass of `kind` with an entry for each field `make` gives one (no pass if none does).
    fn add(&mut self, kind: Kind, make: impl Fn(usize) -> Option<PlanEntry>) {
        let mut any = false;
        let entries: Vec<PlanEntry> = (0..self.slots.len())
            .map(|f| match make(f) {
                Some(mut e) => {
                    any = true;
                    e.on = 1;
                    e.src = self.slots[f];
                    e.coef = (f * self.coef_stride) as u32;
                    if kind.flips() {
                        self.slots[f] ^= 1;
                    }
                    e
                }
                None => PlanEntry::default(),
            })
            .collect();
        if any {
            self.list.push((kind, entries));
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
        let spec = self.spec;
        let GridSpec { nx, ny, .. } = spec;
        let coef_stride = 2 * (nx + ny);
        // Each field's plan (two f64 transcendentals: side by side for a vector env's batch).
        let plans: Option<Vec<StepPlan>> = self
            .fields
            .par_iter_mut()
            .with_min_len(4096)
            .map(|st| StepPlan::new(&spec, &st.params, dt, &mut st.decay_carry))
            .collect();
        let Some(plans) = plans else {
            return Ok(());
        };
        for (fi, (st, plan)) in self.fields.iter_mut().zip(&plans).enumerate() {
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

        let inj: Vec<i32> = self
            .fields
            .iter()
            .map(|s| s.inj_offset.map_or(-1, |o| o as i32))
            .collect();
        let mut passes = Passes {
            list: Vec::new(),
            slots: self.fields.iter().map(|s| s.slot).collect(),
            coef_stride,
        };
        passes.add(Kind::Evaporate, |f| {
            let p = &plans[f];
            // Without a map and with a = 1 the CPU leaves the values as they are (no flush either).
            (!p.diffusion.fuses_decay() && (inj[f] >= 0 || p.a != 1.0)).then_some(PlanEntry {
                inj: inj[f],
                a: p.a,
                b: p.b,
                ..Default::default()
            })
        });
        let max_sub = plans
            .iter()
            .filter_map(|p| match p.diffusion {
                Diffusion::Explicit { substeps, .. } | Diffusion::OneSided { substeps, .. } => {
                    Some(substeps)
                }
                _ => None,
            })
            .max()
            .unwrap_or(0);
        for k in 0..max_sub {
            passes.add(Kind::Explicit, |f| match plans[f].diffusion {
                Diffusion::Explicit { substeps, r } if k < substeps => {
                    let (a, b, i) = if k == 0 {
                        (plans[f].a, plans[f].b, inj[f])
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
        for k in 0..max_sub {
            passes.add(Kind::OneSided, |f| match plans[f].diffusion {
                Diffusion::OneSided { substeps, s } if k < substeps => Some(PlanEntry {
                    inj: -1,
                    r: s,
                    ..Default::default()
                }),
                _ => None,
            });
        }
        passes.add(Kind::XSolve, |f| match plans[f].diffusion {
            Diffusion::Implicit { r } => Some(PlanEntry {
                inj: inj[f],
                a: plans[f].a,
                b: plans[f].b,
                r,
                ..Default::default()
            }),
            _ => None,
        });
        if ny > 1 {
            passes.add(Kind::YSolve, |f| match plans[f].diffusion {
                Diffusion::Implicit { r } => Some(PlanEntry {
                    inj: -1,
                    r,
                    ..Default::default()
                }),
                _ => None,
            });
        }
        if plans.iter().any(|p| p.diffusion == Diffusion::Uniform) {
            // Infinite diffusion (uniform at the mean): finish the passes so far, average on the CPU.
            self.run_passes(&std::mem::take(&mut passes.list));
            for (f, p) in plans.iter().enumerate() {
                if p.diffusion == Diffusion::Uniform {
                    self.fields[f].slot = passes.slots[f];
                    let v = self.read_field(f)?;
                    let mean = (v.iter().map(|&v| v as f64).sum::<f64>() / v.len() as f64) as f32;
                    self.write_field(f, &vec![mean; v.len()])?;
                }
            }
        }
        let max_wind = plans
            .iter()
            .filter_map(|p| p.wind.map(|w| w.substeps))
            .max()
            .unwrap_or(0);
        for k in 0..max_wind {
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
        self.run_passes(&passes.list);
        for (st, s) in self.fields.iter_mut().zip(passes.slots) {
            st.slot = s;
        }
        Ok(())
    }
}
