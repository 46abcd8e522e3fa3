//! The static injection maps of a batch, stored once per distinct map (the worlds of one scenario
//! share theirs), and loading a whole field (values, parameters, map, decay state) from a CPU one.
use super::GpuGrids;
use crate::{GpuError, Result, check_size, storage};
use colcos_sim::field::GridField;

impl GpuGrids {
    /// Sets (or removes) the static injection map `J` of `field`.
    pub fn set_static_injection(&mut self, field: usize, j: Option<&[f32]>) -> Result<()> {
        let ctx = self.ctx.clone();
        ctx.scoped("uploading an injection map", || {
            self.set_static_injection_inner(field, j)
        })?
    }

    /// Overwrites `field` with a CPU field of the batch's spec: its values, parameters, static
    /// injection map and decay state, so that the batch steps it on as the CPU would.
    pub fn load(&mut self, field: usize, from: &GridField) -> Result<()> {
        if *from.spec() != self.spec {
            return Err(GpuError::Invalid(format!(
                "field {field}: a {}x{} grid loaded into a batch of {}x{}",
                from.spec().nx,
                from.spec().ny,
                self.spec.nx,
                self.spec.ny
            )));
        }
        self.write_field(field, from.values())?;
        self.fields[field].params = *from.params();
        self.fields[field].decay_carry = from.decay_carry();
        self.set_static_injection(field, from.static_injection())
    }

    fn set_static_injection_inner(&mut self, field: usize, j: Option<&[f32]>) -> Result<()> {
        let n = self.spec.len();
        let Some(j) = j else {
            self.fields[field].inj_offset = None;
            return Ok(());
        };
        if j.len() != n {
            return Err(GpuError::Invalid(format!(
                "injection map of field {field}: {} values for {n} cells",
                j.len()
            )));
        }
        // A map already stored is shared, never written over (other fields may read it).
        let same = |o: &&u32| self.inj_data[**o as usize..][..n] == *j;
        if let Some(&o) = self.inj_maps.iter().find(same) {
            self.fields[field].inj_offset = Some(o);
            return Ok(());
        }
        if self.inj_maps.len() > self.fields.len() {
            self.compact_maps();
        }
        let off = self.inj_data.len();
        self.inj_data.extend_from_slice(j);
        self.inj_maps.push(off as u32);
        self.fields[field].inj_offset = Some(off as u32);
        let bytes = self.inj_data.len() as u64 * 4;
        check_size(&self.ctx, "static injection maps", bytes)?;
        if self.inj_data.len() as u32 > self.inj_len {
            // Room for as many maps again, so that a batch loading many distinct maps grows rarely.
            let room = (2 * self.inj_data.len()) as u64 * 4;
            let room = if room <= self.ctx.max_binding() {
                room
            } else {
                bytes
            };
            self.inj = storage(
                &self.ctx,
                "colcos injection maps",
                room,
                wgpu::BufferUsages::empty(),
            );
            self.inj_len = (room / 4) as u32;
            self.bind = None;
            self.ctx
                .queue
                .write_buffer(&self.inj, 0, bytemuck::cast_slice(&self.inj_data));
        } else {
            self.ctx
                .queue
                .write_buffer(&self.inj, off as u64 * 4, bytemuck::cast_slice(j));
        }
        Ok(())
    }

    /// Drops the stored maps no field uses any more (more distinct maps than fields: some are
    /// unused), keeping the others' data in a new, compact order.
    fn compact_maps(&mut self) {
        let n = self.spec.len();
        let mut data = Vec::new();
        let mut maps: Vec<u32> = Vec::new();
        let mut moved: Vec<(u32, u32)> = Vec::new();
        for f in &mut self.fields {
            let Some(old) = f.inj_offset else { continue };
            let new = match moved.iter().find(|(o, _)| *o == old) {
                Some(&(_, new)) => new,
                None => {
                    let new = data.len() as u32;
                    data.extend_from_slice(&self.inj_data[old as usize..][..n]);
                    maps.push(new);
                    moved.push((old, new));
                    new
                }
            };
            f.inj_offset = Some(new);
        }
        self.inj_data = data;
        self.inj_maps = maps;
        if !self.inj_data.is_empty() {
            self.ctx
                .queue
                .write_buffer(&self.inj, 0, bytemuck::cast_slice(&self.inj_data));
        }
    }
}
