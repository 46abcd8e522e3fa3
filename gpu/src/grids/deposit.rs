//! Trail deposits on a batch, in rounds: the k-th deposit of every field in round k, so a field's
//! deposits are summed in the order given.
use super::record::{Dispatch, Grown, Kind, MAX_GROUPS, PassUniform, groups};
use super::{GpuGrids, Scratch};
use crate::program::shader_struct;
use crate::{GpuError, Result};
use colcos_sim::field::{GridSpec, Kernel};
use glam::Vec2;
use rayon::prelude::*;

/// Fewest deposits a thread takes when records are made side by side.
const PARALLEL_MIN: usize = 4096;

/// One trail deposit: `amount * kernel(distance to segment a-b)` added to every cell near the segment
/// of field `field`, exactly as
/// [`GridField::deposit_segment`](colcos_sim::field::GridField::deposit_segment).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Deposit {
    pub field: usize,
    pub kernel: Kernel,
    pub a: Vec2,
    pub b: Vec2,
    pub amount: f32,
}

shader_struct! {
    /// One deposit as the shader reads it: the cells of its box and the kernel's segment.
    pub(crate) struct DepRecord as Dep {
        field: u32,
        slot: u32,
        i0: u32,
        j0: u32,
        w: u32,
        h: u32,
        /// 0 disc, 1 cone, 2 Gaussian.
        kind: u32,
        _pad: u32,
        ax: f32,
        ay: f32,
        abx: f32,
        aby: f32,
        len2: f32,
        support: f32,
        /// Radius or sigma.
        param: f32,
        amount: f32,
    }
}

const _: () = assert!(std::mem::size_of::<DepRecord>() == 64);

impl GpuGrids {
    /// Adds trail deposits, in order (deposits on one field are summed in the order given, as a
    /// sequence of [`GridField::deposit_segment`](colcos_sim::field::GridField::deposit_segment)
    /// calls would).
    pub fn deposit(&mut self, deposits: &[Deposit]) -> Result<()> {
        let ctx = self.ctx.clone();
        ctx.scoped("depositing trails", || self.deposit_inner(deposits))?
    }

    /// The record of deposit `d` (`None`: it lays nothing), as the shader reads it; `d.field` is
    /// one of the batch's.
    pub(crate) fn deposit_record(&self, d: &Deposit) -> Option<DepRecord> {
        let support = d.kernel.support();
        if support.is_nan() || support < 0.0 || !d.a.is_finite() || !d.b.is_finite() {
            return None;
        }
        let (a, b) = (d.a, d.b);
        let ((i0, i1), (j0, j1)) = self.spec.segment_cells(a, b, support);
        if i1 <= i0 || j1 <= j0 {
            return None;
        }
        let ab = b - a;
        let (kind, param) = match d.kernel {
            Kernel::Disc { radius } => (0, radius),
            Kernel::Cone { radius } => (1, radius),
            Kernel::Gaussian { sigma } => (2, sigma),
        };
        Some(DepRecord {
            field: d.field as u32,
            slot: self.fields[d.field].slot,
            i0: i0 as u32,
            j0: j0 as u32,
            w: (i1 - i0) as u32,
            h: (j1 - j0) as u32,
            kind,
            _pad: 0,
            ax: a.x,
            ay: a.y,
            abx: ab.x,
            aby: ab.y,
            len2: ab.length_squared(),
            support,
            param,
            amount: d.amount,
        })
    }

    fn deposit_inner(&mut self, deposits: &[Deposit]) -> Result<()> {
        if let Some(d) = deposits.iter().find(|d| d.field >= self.fields.len()) {
            return Err(GpuError::Invalid(format!(
                "deposit on field {} of {}",
                d.field,
                self.fields.len()
            )));
        }
        // The records side by side (a vector env's batch lays tens of thousands a step), into
        // buffers kept from step to step ...
        let mut scratch = std::mem::take(&mut self.scratch);
        let made = &mut scratch.made;
        made.clear();
        made.par_extend(
            deposits
                .par_iter()
                .with_min_len(PARALLEL_MIN)
                .map(|d| self.deposit_record(d)),
        );
        // ... then each field's k-th deposit into round k, rounds one after the other: `order`
        // lists the deposits round by round.
        let per_field = &mut scratch.per_field;
        per_field.clear();
        per_field.resize(self.fields.len(), 0);
        let round_of = &mut scratch.round_of;
        round_of.clear();
        let mut sizes: Vec<usize> = Vec::new();
        let mut cells: Vec<usize> = Vec::new();
        round_of.extend(made.iter().map(|r| {
            let Some(r) = r else { return u32::MAX };
            let k = per_field[r.field as usize];
            per_field[r.field as usize] += 1;
            if sizes.len() <= k as usize {
                sizes.push(0);
                cells.push(0);
            }
            sizes[k as usize] += 1;
            cells[k as usize] = cells[k as usize].max((r.w * r.h) as usize);
            k
        }));
        let Scratch {
            made,
            round_of,
            order,
            recs,
            ..
        } = &mut scratch;
        let result = self.lay_rounds(made, round_of, (order, recs), (&sizes, &cells));
        self.scratch = scratch;
        result
    }

    /// Lays deposits whose records were made before the step that precedes them (a vector env's
    /// batch makes them while queueing its worlds' trails): `made[i]` (`None`: it lays nothing) in
    /// round `rounds[i]`, a field's k-th deposit in round k. Each record's slot is set to its
    /// field's current one first.
    pub(crate) fn deposit_made(
        &mut self,
        made: &mut [Option<DepRecord>],
        rounds: &[u32],
    ) -> Result<()> {
        let ctx = self.ctx.clone();
        ctx.scoped("depositing trails", || {
            let fields = &self.fields;
            if let Some(r) = made
                .iter()
                .flatten()
                .find(|r| r.field as usize >= fields.len())
            {
                return Err(GpuError::Invalid(format!(
                    "deposit on field {} of {}",
                    r.field,
                    fields.len()
                )));
            }
            (made.par_iter_mut().with_min_len(PARALLEL_MIN))
                .flatten()
                .for_each(|r| r.slot = fields[r.field as usize].slot);
            let mut sizes: Vec<usize> = Vec::new();
            let mut cells: Vec<usize> = Vec::new();
            for (r, &k) in made.iter().zip(rounds) {
                if let Some(r) = r {
                    let k = k as usize;
                    if sizes.len() <= k {
                        sizes.resize(k + 1, 0);
                        cells.resize(k + 1, 0);
                    }
                    sizes[k] += 1;
                    cells[k] = cells[k].max((r.w * r.h) as usize);
                }
            }
            let mut scratch = std::mem::take(&mut self.scratch);
            let result = self.lay_rounds(
                made,
                rounds,
                (&mut scratch.order, &mut scratch.recs),
                (&sizes, &cells),
            );
            self.scratch = scratch;
            result
        })?
    }

    /// Uploads the records of `made` round by round (`made[i]` in round `round_of[i]`; `sizes[k]`
    /// records in round `k`, the largest covering `cells[k]` cells) through `order` and `recs`, and
    /// records their dispatches.
    fn lay_rounds(
        &mut self,
        made: &[Option<DepRecord>],
        round_of: &[u32],
        (order, recs): (&mut Vec<u32>, &mut Vec<DepRecord>),
        (sizes, cells): (&[usize], &[usize]),
    ) -> Result<()> {
        let GridSpec { nx, ny, cell } = self.spec;
        if sizes.is_empty() {
            return Ok(());
        }
        if sizes.iter().any(|&n| n > MAX_GROUPS as usize) {
            return Err(GpuError::Invalid(format!(
                "more than {MAX_GROUPS} fields with a deposit in one call: split the call"
            )));
        }
        let mut next: Vec<usize> = sizes
            .iter()
            .scan(0, |start, &n| {
                let s = *start;
                *start += n;
                Some(s)
            })
            .collect();
        order.clear();
        order.resize(sizes.iter().sum(), 0);
        for (i, (r, &k)) in made.iter().zip(round_of).enumerate() {
            if r.is_some() {
                order[next[k as usize]] = i as u32;
                next[k as usize] += 1;
            }
        }
        recs.clear();
        recs.par_extend(
            order
                .par_iter()
                .with_min_len(PARALLEL_MIN)
                .map(|&i| made[i as usize].unwrap_or_default()),
        );
        self.ensure(
            Grown::Deposits,
            std::mem::size_of_val(recs.as_slice()) as u64,
        );
        self.ctx
            .queue
            .write_buffer(&self.deps, 0, bytemuck::cast_slice(recs));
        let mut first = 0u32;
        let dispatches: Vec<Dispatch> = sizes
            .iter()
            .zip(cells)
            .map(|(&size, &cells)| {
                let (gx, gy) = groups(cells, 256);
                let count = size as u32;
                let uniform = PassUniform {
                    index: first,
                    nfields: self.fields.len() as u32,
                    nx: nx as u32,
                    ny: ny as u32,
                    groups_x: gx,
                    count,
                    cell,
                    _pad: 0,
                };
                first += count;
                Dispatch {
                    kind: Kind::Deposit,
                    uniform,
                    groups: [gx, gy, count],
                }
            })
            .collect();
        self.record("colcos deposits", &dispatches);
        Ok(())
    }
}
