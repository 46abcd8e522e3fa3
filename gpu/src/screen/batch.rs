//! Sensing a batch of worlds every step from buffers kept between steps: each sensor goes up as its
//! centre (8 bytes) and, when it changes, the index of its footprint's set of offsets; the GPU adds
//! them (`offset + centre`, the f32 sums of the CPU's `ColourSensor::sample_points`), composes the
//! screen at the points from the grid fields and sums the levels. Sets of offsets are shared by every
//! sensor with the same footprint (a scenario's sensors, unless randomised).
use super::{GpuScreen, LayerRec, POINTS_PER_SENSOR, Uni, groups};
use crate::program::bind_buffers;
use crate::{GpuContext, GpuGrids, Result, check_size, storage};
use colcos_sim::screen::ScreenSpec;
use glam::Vec2;
use std::collections::HashMap;
use std::sync::Arc;

/// The footprints' sets of offsets, [`POINTS_PER_SENSOR`] a set, each stored once.
pub struct FootprintSets {
    ctx: Arc<GpuContext>,
    data: Vec<[f32; 2]>,
    index: HashMap<[u32; 2 * POINTS_PER_SENSOR], u32>,
    buffer: wgpu::Buffer,
    /// Bumped when `buffer` is replaced (bind groups made with the old one are stale).
    generation: u64,
    uploaded: usize,
}

impl FootprintSets {
    pub fn new(ctx: Arc<GpuContext>) -> Result<Self> {
        let buffer = ctx.scoped("allocating the footprint offsets", || {
            storage(
                &ctx,
                "colcos footprint offsets",
                4096,
                wgpu::BufferUsages::empty(),
            )
        })?;
        Ok(FootprintSets {
            ctx,
            data: Vec::new(),
            index: HashMap::new(),
            buffer,
            generation: 0,
            uploaded: 0,
        })
    }

    /// The index of the set `offsets` (added if new).
    pub fn set_of(&mut self, offsets: &[Vec2; POINTS_PER_SENSOR]) -> u32 {
        let key: [u32; 2 * POINTS_PER_SENSOR] =
            std::array::from_fn(|k| offsets[k / 2][k % 2].to_bits());
        let next = (self.data.len() / POINTS_PER_SENSOR) as u32;
        *self.index.entry(key).or_insert_with(|| {
            self.data.extend(offsets.iter().map(|o| [o.x, o.y]));
            next
        })
    }

    /// Uploads the sets added since the last call (a larger buffer when they outgrow it).
    fn upload(&mut self) -> Result<()> {
        if self.uploaded == self.data.len() {
            return Ok(());
        }
        let bytes = self.data.len() as u64 * 8;
        check_size(&self.ctx, "footprint offsets", bytes)?;
        let ctx = self.ctx.clone();
        ctx.scoped("uploading the footprint offsets", || {
            if bytes > self.buffer.size() {
                let room = (2 * bytes).min(ctx.max_binding()).max(bytes);
                self.buffer = storage(
                    &ctx,
                    "colcos footprint offsets",
                    room,
                    wgpu::BufferUsages::empty(),
                );
                self.generation += 1;
                self.uploaded = 0;
            }
            let new = &self.data[self.uploaded..];
            ctx.queue.write_buffer(
                &self.buffer,
                self.uploaded as u64 * 8,
                bytemuck::cast_slice(new),
            );
            self.uploaded = self.data.len();
        })
    }
}

/// The buffers of one batch's sensing: `per_world` sensors for each of `worlds` worlds.
pub struct SensorBatch {
    per_world: usize,
    count: usize,
    centres: wgpu::Buffer,
    sets: wgpu::Buffer,
    layers: wgpu::Buffer,
    uniform: wgpu::Buffer,
    out: wgpu::Buffer,
    /// The bind group, and the generation of the footprint sets it binds.
    bind: Option<(wgpu::BindGroup, u64)>,
    /// The layer records last uploaded (they change only where a field's slot does).
    layer_recs: Vec<LayerRec>,
}

impl SensorBatch {
    /// The GPU buffer of the sums of the last [`GpuScreen::record_batch`] (three u32 per sensor).
    pub fn out(&self) -> &wgpu::Buffer {
        &self.out
    }
    /// Sensors in the batch.
    pub fn len(&self) -> usize {
        self.count
    }
    pub fn is_empty(&self) -> bool {
        self.count == 0
    }
}

impl GpuScreen {
    /// Buffers for sensing `worlds` worlds of `nlayers` grid layers and `per_world` sensors each.
    pub fn sensor_batch(
        &self,
        worlds: usize,
        per_world: usize,
        nlayers: usize,
    ) -> Result<SensorBatch> {
        let count = worlds * per_world;
        check_size(&self.ctx, "sensor sums", count as u64 * 12)?;
        let ctx = &self.ctx;
        ctx.scoped("allocating the sensing buffers", || {
            let buf =
                |label: &str, bytes: u64| storage(ctx, label, bytes, wgpu::BufferUsages::empty());
            SensorBatch {
                per_world,
                count,
                centres: buf("colcos sensor centres", count as u64 * 8),
                sets: buf("colcos sensor footprint sets", count as u64 * 4),
                layers: buf("colcos batch layers", (worlds * nlayers) as u64 * 32),
                uniform: ctx.device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("colcos sensing uniform"),
                    size: std::mem::size_of::<Uni>() as u64,
                    usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                }),
                out: buf("colcos sensor sums", count as u64 * 12),
                layer_recs: Vec::new(),
                bind: None,
            }
        })
    }

    /// Records into `enc` the sensing of every sensor of `batch` on `grids`' fields, whose screens
    /// are `colours` (one per grid layer, field `world * colours.len() + j`): `centres` (one per
    /// sensor, world by world) go up, and `sets` (each sensor's footprint set) where given. The sums
    /// land in [`SensorBatch::out`].
    #[allow(clippy::too_many_arguments)]
    pub fn record_batch(
        &self,
        enc: &mut wgpu::CommandEncoder,
        grids: &GpuGrids,
        colours: &[[f32; 3]],
        batch: &mut SensorBatch,
        footprints: &mut FootprintSets,
        centres: &[[f32; 2]],
        sets: Option<&[u32]>,
        screen: &ScreenSpec,
    ) -> Result<()> {
        if centres.len() != batch.count || sets.is_some_and(|s| s.len() != batch.count) {
            return Err(crate::GpuError::Invalid(format!(
                "{} sensor centres for a batch of {} sensors",
                centres.len(),
                batch.count
            )));
        }
        if batch.count == 0 {
            return Ok(());
        }
        footprints.upload()?;
        let nl = colours.len();
        let worlds = batch.count / batch.per_world.max(1);
        let mut layers_changed = batch.layer_recs.len() != worlds * nl;
        batch.layer_recs.resize(worlds * nl, LayerRec::default());
        for (f, rec) in batch.layer_recs.iter_mut().enumerate() {
            let now = LayerRec {
                kind: 0,
                offset: grids.field_offset(f) as u32,
                count: 0,
                _pad: 0,
                k: colours[f % nl],
                time: 0.0,
            };
            if *rec != now {
                *rec = now;
                layers_changed = true;
            }
        }
        let (gx, gy) = groups(batch.count, 64);
        let spec = grids.spec();
        let ps = screen.pixel_size();
        let uni = Uni {
            width: POINTS_PER_SENSOR as u32,
            height: batch.per_world as u32,
            nlayers: nl as u32,
            nx: spec.nx as u32,
            ny: spec.ny as u32,
            groups_x: gx,
            count: batch.count as u32,
            cell: spec.cell,
            ps_x: ps.x,
            ps_y: ps.y,
            res_x: screen.resolution[0],
            res_y: screen.resolution[1],
            ..Default::default()
        };
        self.ctx.scoped("sensing the batch", || {
            let q = &self.ctx.queue;
            q.write_buffer(&batch.centres, 0, bytemuck::cast_slice(centres));
            if let Some(sets) = sets {
                q.write_buffer(&batch.sets, 0, bytemuck::cast_slice(sets));
            }
            if layers_changed {
                q.write_buffer(&batch.layers, 0, bytemuck::cast_slice(&batch.layer_recs));
            }
            q.write_buffer(&batch.uniform, 0, bytemuck::bytes_of(&uni));
            if batch
                .bind
                .as_ref()
                .is_none_or(|(_, g)| *g != footprints.generation)
            {
                let buffers = [
                    grids.values_buffer(),
                    &batch.layers,
                    &self.dummy,
                    &batch.uniform,
                    &batch.out,
                    &batch.centres,
                    &batch.sets,
                    &footprints.buffer,
                ];
                let bind = bind_buffers(
                    &self.ctx.device,
                    &self.layout,
                    "colcos batch sensing",
                    &buffers,
                );
                batch.bind = Some((bind, footprints.generation));
            }
            let bind = &batch.bind.as_ref().expect("made above").0;
            let mut pass = enc.begin_compute_pass(&Default::default());
            pass.set_pipeline(&self.sense_centres);
            pass.set_bind_group(0, bind, &[]);
            pass.dispatch_workgroups(gx, gy, 1);
        })
    }
}
