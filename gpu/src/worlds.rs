//! Many worlds' grid pheromones resident on the GPU (a vector environment's): each step's field
//! passes, every world's trail deposits and every robot's colour sensing as one dispatch sequence,
//! and only the sensors' level sums read back.
//!
//! The worlds share one scenario, so their grids have one spec: world `w`'s pheromone `j` is field
//! `w * P + j` of a [`GpuGrids`] batch (`P` pheromones a world). A batch larger than the adapter's
//! largest storage binding is cut into parts of whole worlds, each stepped and sensed on its own.
use crate::grids::DepRecord;
use crate::screen::{FootprintSets, GpuScreen, POINTS_PER_SENSOR, SensorBatch};
use crate::{Deposit, GpuContext, GpuError, GpuGrids, Result, storage};
use colcos_sim::field::{FieldModel, GridField, GridParams, GridSpec, Pheromone};
use colcos_sim::screen::ScreenSpec;
use colcos_sim::world::TrailSegment;
use glam::Vec2;
use rayon::prelude::*;
use std::sync::Arc;

/// Most fields one part may hold (the batch's workgroup limit along z).
const MAX_PART_FIELDS: usize = 65_535;

/// Worlds `first..first + worlds` of the batch: their grids and their sensing buffers.
struct Part {
    first: usize,
    worlds: usize,
    grids: GpuGrids,
    sensing: SensorBatch,
    /// The queued trails' deposit records (`None`: lays nothing) and their rounds (a field's k-th
    /// deposit of the step in round k; a world's fields are its own, so rounds are counted per world).
    made: Vec<Option<DepRecord>>,
    rounds: Vec<u32>,
}

/// The grid pheromones of `worlds` worlds of one scenario, on one device.
pub struct WorldFields {
    ctx: Arc<GpuContext>,
    spec: GridSpec,
    screen_spec: ScreenSpec,
    /// Pheromones a world has (all grids), and their colours.
    per_world: usize,
    colours: Vec<[f32; 3]>,
    parts: Vec<Part>,
    screen: GpuScreen,
    /// Colour sensors a world has.
    sensors: usize,
    /// Every sensor's centre this step, `[E, sensors]`.
    centres: Vec<[f32; 2]>,
    /// Every sensor's footprint (a set of [`FootprintSets`]), `[E, sensors]`, and whether it changed
    /// since the last upload.
    sets: Vec<u32>,
    sets_changed: bool,
    footprints: FootprintSets,
    /// Every part's sums together, for one read-back (several parts only).
    all_sums: Option<wgpu::Buffer>,
}

/// Why a world's pheromones cannot live in a [`WorldFields`] batch, or `None` if they can: every
/// pheromone a grid, all of one spec.
pub fn unsupported(pheromones: &[Pheromone]) -> Option<String> {
    let mut spec = None;
    for p in pheromones {
        match &p.model {
            FieldModel::Grid(g) => {
                if spec.is_some_and(|s| s != *g.spec()) {
                    return Some("the grid pheromones have different grids".into());
                }
                spec = Some(*g.spec());
            }
            FieldModel::Gaussian(_) => {
                return Some(format!("pheromone {:?} is Gaussian", p.name));
            }
        }
    }
    spec.is_none().then(|| "no grid pheromones".into())
}

fn grids_of(pheromones: &[Pheromone]) -> impl Iterator<Item = &GridField> {
    pheromones.iter().filter_map(|p| match &p.model {
        FieldModel::Grid(g) => Some(g),
        FieldModel::Gaussian(_) => None,
    })
}

impl WorldFields {
    /// A batch of `worlds` worlds whose pheromones are like `pheromones` (colours, grid, parameters),
    /// all zero until [`WorldFields::load_world`], with `sensors` colour sensors a world; `screen` is
    /// the scenario's screen.
    pub fn new(
        ctx: Arc<GpuContext>,
        pheromones: &[Pheromone],
        worlds: usize,
        sensors: usize,
        screen: ScreenSpec,
    ) -> Result<Self> {
        Self::in_parts(ctx, pheromones, worlds, sensors, screen, usize::MAX)
    }

    /// [`WorldFields::new`] with at most `part` worlds a part (fewer where the adapter's bindings
    /// hold fewer): smaller buffers, and a way to test batches of several parts.
    pub fn in_parts(
        ctx: Arc<GpuContext>,
        pheromones: &[Pheromone],
        worlds: usize,
        sensors: usize,
        screen: ScreenSpec,
        part: usize,
    ) -> Result<Self> {
        if let Some(why) = unsupported(pheromones) {
            return Err(GpuError::Invalid(why));
        }
        let first = grids_of(pheromones).next().expect("checked above");
        let spec = *first.spec();
        let params: Vec<GridParams> = grids_of(pheromones).map(|g| *g.params()).collect();
        let per_world = params.len();
        // Worlds a part: as many as one binding of two slots per field holds.
        let world_bytes = 2 * spec.len() as u64 * per_world as u64 * 4;
        let fit = (ctx.max_binding() / world_bytes.max(1)) as usize;
        let per_part = fit.min(MAX_PART_FIELDS / per_world).min(part).max(1);
        let gpu_screen = GpuScreen::new(ctx.clone())?;
        let mut parts = Vec::new();
        let mut first_world = 0;
        while first_world < worlds {
            let n = per_part.min(worlds - first_world);
            let all: Vec<GridParams> = (0..n).flat_map(|_| params.iter().copied()).collect();
            parts.push(Part {
                first: first_world,
                worlds: n,
                grids: GpuGrids::new(ctx.clone(), spec, &all)?,
                sensing: gpu_screen.sensor_batch(n, sensors, per_world)?,
                made: Vec::new(),
                rounds: Vec::new(),
            });
            first_world += n;
        }
        let all_sums = match parts.len() {
            1 => None,
            _ => Some(ctx.scoped("allocating the sensor sums", || {
                storage(
                    &ctx,
                    "colcos all sensor sums",
                    (worlds * sensors) as u64 * 12,
                    wgpu::BufferUsages::empty(),
                )
            })?),
        };
        Ok(WorldFields {
            screen: gpu_screen,
            footprints: FootprintSets::new(ctx.clone())?,
            ctx,
            spec,
            screen_spec: screen,
            per_world,
            colours: pheromones.iter().map(|p| p.colour).collect(),
            parts,
            sensors,
            centres: vec![[0.0; 2]; worlds * sensors],
            sets: vec![0; worlds * sensors],
            sets_changed: true,
            all_sums,
        })
    }

    pub fn context(&self) -> &Arc<GpuContext> {
        &self.ctx
    }
    /// Worlds in the batch.
    pub fn len(&self) -> usize {
        self.parts.iter().map(|p| p.worlds).sum()
    }
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
    /// How many parts the batch is cut into (one where the adapter's bindings hold every world).
    pub fn parts(&self) -> usize {
        self.parts.len()
    }
    pub fn spec(&self) -> &GridSpec {
        &self.spec
    }

    /// The part of world `w` and the world's index in it.
    fn locate(&self, w: usize) -> Result<(usize, usize)> {
        let k = self
            .parts
            .iter()
            .position(|p| (p.first..p.first + p.worlds).contains(&w))
            .ok_or_else(|| {
                GpuError::Invalid(format!("world {w} of a batch of {} worlds", self.len()))
            })?;
        Ok((k, w - self.parts[k].first))
    }

    /// Overwrites world `w`'s fields with `pheromones`' (a world just built: values, parameters,
    /// static maps, decay state).
    pub fn load_world(&mut self, w: usize, pheromones: &[Pheromone]) -> Result<()> {
        let (k, i) = self.locate(w)?;
        if grids_of(pheromones).count() != self.per_world || pheromones.len() != self.per_world {
            return Err(GpuError::Invalid(format!(
                "world {w}: {} pheromones for a batch of {} grid pheromones a world",
                pheromones.len(),
                self.per_world
            )));
        }
        let part = &mut self.parts[k];
        for (j, g) in grids_of(pheromones).enumerate() {
            part.grids.load(i * self.per_world + j, g)?;
        }
        Ok(())
    }

    /// World `w`'s field values, one `Vec` per pheromone (blocking).
    pub fn read_world(&self, w: usize) -> Result<Vec<Vec<f32>>> {
        let (k, i) = self.locate(w)?;
        (0..self.per_world)
            .map(|j| self.parts[k].grids.read_field(i * self.per_world + j))
            .collect()
    }

    /// Every world's field values (blocking; one read-back a part): `[world][pheromone][cell]`.
    pub fn read_all(&self) -> Result<Vec<Vec<Vec<f32>>>> {
        let mut out = Vec::with_capacity(self.len());
        for part in &self.parts {
            let mut fields = part.grids.read_all()?.into_iter();
            for _ in 0..part.worlds {
                out.push(fields.by_ref().take(self.per_world).collect());
            }
        }
        Ok(out)
    }

    /// Queues every world's trail segments of this step for [`WorldFields::step`] (replacing any queued
    /// before), world by world and in order, side by side: `trails(w)` is world `w`'s, `None` for a
    /// world that does not step. A trail on a pheromone the worlds lack queues nothing and is an error.
    pub fn queue_trails<'a>(
        &mut self,
        trails: impl Fn(usize) -> Option<&'a [TrailSegment]> + Sync,
    ) -> Result<()> {
        let per_world = self.per_world;
        let mut bad = None;
        for part in &mut self.parts {
            let Part {
                first,
                worlds,
                grids,
                made,
                rounds,
                ..
            } = part;
            let first = *first;
            // Each world's records and rounds into its own stretch of the part's lists, side by side.
            let counts: Vec<usize> = (0..*worlds)
                .map(|i| trails(first + i).map_or(0, <[_]>::len))
                .collect();
            let total = counts.iter().sum();
            made.clear();
            made.resize(total, None);
            rounds.clear();
            rounds.resize(total, u32::MAX);
            let mut stretches = Vec::with_capacity(*worlds);
            let (mut made_rest, mut rounds_rest) = (&mut made[..], &mut rounds[..]);
            for &n in &counts {
                let (m, m_tail) = made_rest.split_at_mut(n);
                let (r, r_tail) = rounds_rest.split_at_mut(n);
                stretches.push((m, r));
                (made_rest, rounds_rest) = (m_tail, r_tail);
            }
            let grids = &*grids;
            let found = (stretches.into_par_iter().enumerate())
                .with_min_len(256)
                .filter_map(|(i, (made, rounds))| {
                    let segments = trails(first + i).unwrap_or_default();
                    for (k, s) in segments.iter().enumerate() {
                        if s.pheromone >= per_world {
                            return Some((first + i, s.pheromone));
                        }
                        made[k] = grids.deposit_record(&Deposit {
                            field: i * per_world + s.pheromone,
                            kernel: s.kernel,
                            a: s.from,
                            b: s.to,
                            amount: s.amount,
                        });
                        if made[k].is_some() {
                            // The deposits this world laid before on the same pheromone.
                            let before = (0..k)
                                .filter(|&j| {
                                    segments[j].pheromone == s.pheromone && made[j].is_some()
                                })
                                .count();
                            rounds[k] = before as u32;
                        }
                    }
                    None
                })
                .min_by_key(|&(w, _)| w);
            bad = bad.or(found);
        }
        if let Some((w, pheromone)) = bad {
            for part in &mut self.parts {
                part.made.clear();
                part.rounds.clear();
            }
            return Err(GpuError::Invalid(format!(
                "world {w}: a trail on pheromone {pheromone} of {per_world}"
            )));
        }
        Ok(())
    }

    /// The index of the footprint whose sample points are `offsets` from a sensor's centre (see
    /// [`colcos_sim::sensors::ColourSensor::sample_points`]), for [`WorldFields::set_footprints`].
    pub fn footprint(&mut self, offsets: &[Vec2; POINTS_PER_SENSOR]) -> u32 {
        self.footprints.set_of(offsets)
    }

    /// Sets world `w`'s sensors' footprints (one index of [`WorldFields::footprint`] per sensor).
    pub fn set_footprints(&mut self, w: usize, sets: &[u32]) -> Result<()> {
        if w >= self.len() || sets.len() != self.sensors {
            return Err(GpuError::Invalid(format!(
                "world {w}: {} footprints for {} sensors (worlds: {})",
                sets.len(),
                self.sensors,
                self.len()
            )));
        }
        self.sets[w * self.sensors..][..self.sensors].copy_from_slice(sets);
        self.sets_changed = true;
        Ok(())
    }

    /// Every sensor's centre for the next [`WorldFields::sense`], `[E, sensors]` (world by world, a
    /// world's sensors in the order of its footprints).
    pub fn centres_mut(&mut self) -> &mut [[f32; 2]] {
        &mut self.centres
    }

    /// Colour sensors a world has.
    pub fn sensors(&self) -> usize {
        self.sensors
    }

    /// Steps every world's fields by `dt` (the passes of [`GridField::step`]), then lays the trail
    /// segments queued since the last call, in the order of a world's step on the CPU.
    pub fn step(&mut self, dt: f32) -> Result<()> {
        for part in &mut self.parts {
            part.grids.step(dt)?;
            part.grids.deposit_made(&mut part.made, &part.rounds)?;
            part.made.clear();
            part.rounds.clear();
        }
        Ok(())
    }

    /// The 8-bit screen level sums (r, g, b) of every sensor at its centre of
    /// [`WorldFields::centres_mut`] and its footprint, `[E, sensors]`, at the fields as they are now:
    /// one dispatch a part, one read-back.
    pub fn sense(&mut self, out: &mut Vec<[u32; 3]>) -> Result<()> {
        let s = self.sensors;
        out.clear();
        if self.parts.is_empty() {
            return Ok(());
        }
        let mut enc = self.ctx.device.create_command_encoder(&Default::default());
        for part in &mut self.parts {
            let range = part.first * s..(part.first + part.worlds) * s;
            let sets = self.sets_changed.then(|| &self.sets[range.clone()]);
            self.screen.record_batch(
                &mut enc,
                &part.grids,
                &self.colours,
                &mut part.sensing,
                &mut self.footprints,
                &self.centres[range],
                sets,
                &self.screen_spec,
            )?;
            if let Some(all) = &self.all_sums {
                let bytes = part.sensing.len() as u64 * 12;
                enc.copy_buffer_to_buffer(
                    part.sensing.out(),
                    0,
                    all,
                    part.first as u64 * s as u64 * 12,
                    bytes,
                );
            }
        }
        self.sets_changed = false;
        self.ctx
            .scoped("sensing", || self.ctx.queue.submit([enc.finish()]))?;
        let src = match &self.all_sums {
            Some(all) => all,
            None => self.parts[0].sensing.out(),
        };
        self.ctx
            .read_buffer_with(src, 0, self.centres.len() as u64 * 12, |bytes| {
                match bytemuck::try_cast_slice::<u8, [u32; 3]>(bytes) {
                    Ok(sums) => out.extend_from_slice(sums),
                    // A mapping not aligned to 4 bytes (none seen): element by element.
                    Err(_) => out.extend(bytes.chunks_exact(12).map(|c| {
                        let u = |k: usize| u32::from_ne_bytes([c[k], c[k + 1], c[k + 2], c[k + 3]]);
                        [u(0), u(4), u(8)]
                    })),
                }
            })?;
        Ok(())
    }
}
