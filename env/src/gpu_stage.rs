//! The field stage of a batch on the GPU: every world's grid pheromones resident in one
//! [`colcos_gpu::WorldFields`] batch for the environment's life. A step's worlds move on the CPU, then
//! this stage steps all their fields, lays all their trails and senses every robot's colour sensors
//! in one dispatch sequence, and only the sensors' level sums come back; the worlds then read them
//! into observations (`World::sense_from_sums`) and the tasks hand out rewards on the CPU.
//!
//! A world built on the CPU (a new episode, its fields on the CPU) is loaded into the batch before the
//! first step it steps in; until then the batch's copy of its fields is stale and unused (its
//! sensors' sums this step are not read).
use crate::GPU_STAGE_PARTS;
use crate::error::{EnvError, Result};
use crate::world_slot::WorldSlot;
use crate::world_step::Begun;
use colcos_sim::field::{FieldModel, GridField, Pheromone};
use colcos_sim::world::TrailSegment;
use rayon::prelude::*;

/// A GPU error as the environment's.
fn backend_error(e: colcos_gpu::GpuError) -> EnvError {
    EnvError::Backend(format!("GPU field stage: {e}"))
}

/// The batch's grids on the GPU, and the sums of the last step's sensing.
pub(crate) struct GpuStage {
    fields: colcos_gpu::WorldFields,
    /// Footprint level sums of the last sensing, four per robot, `[E, R, 4]`.
    sums: Vec<[u32; 3]>,
    /// Robots a world has.
    robots: usize,
    /// How each world began the current step.
    pub(crate) begun: Vec<Begun>,
    /// Seconds spent in the parts of the steps so far, as [`GPU_STAGE_PARTS`] names them.
    pub(crate) seconds: [f64; GPU_STAGE_PARTS.len()],
}

impl GpuStage {
    /// The batch of `slots`' worlds where `backend` keeps their grids in one, each world's loaded.
    pub(crate) fn for_backend(
        backend: &crate::backend::EnvBackend,
        slots: &mut [WorldSlot],
    ) -> Result<Option<Self>> {
        match backend.batch_context() {
            Some(ctx) => Self::new(ctx.clone(), slots).map(Some),
            None => Ok(None),
        }
    }

    /// The batch of `slots`' worlds on `ctx`, each world's grids loaded.
    pub(crate) fn new(
        ctx: std::sync::Arc<colcos_gpu::GpuContext>,
        slots: &mut [WorldSlot],
    ) -> Result<Self> {
        let first = &slots[0].world;
        let fields = colcos_gpu::WorldFields::new(
            ctx,
            first.pheromones(),
            slots.len(),
            4 * first.robot_count(),
            *first.screen(),
        )
        .map_err(backend_error)?;
        let mut stage = GpuStage {
            fields,
            sums: Vec::new(),
            robots: first.robot_count(),
            begun: vec![Begun::Stepped; slots.len()],
            seconds: [0.0; GPU_STAGE_PARTS.len()],
        };
        stage.load_fresh(slots, |_| true)?;
        Ok(stage)
    }

    /// Loads the worlds that are fresh and for which `now(w)` holds: their fields and their sensors'
    /// footprints.
    fn load_fresh(
        &mut self,
        slots: &mut [WorldSlot],
        now: impl Fn(usize) -> bool + Sync,
    ) -> Result<()> {
        // Found side by side: a serial look at every world costs a cache miss each (worlds lie
        // apart on the heap), a millisecond for 16,384 worlds.
        let fresh: Vec<usize> = (slots.par_iter_mut().enumerate())
            .filter(|(w, slot)| slot.fresh && now(*w))
            .map(|(w, _)| w)
            .collect();
        let mut sets = Vec::with_capacity(4 * self.robots);
        for w in fresh {
            let slot = &mut slots[w];
            let world = &slot.world;
            (self.fields)
                .load_world(w, world.pheromones())
                .map_err(backend_error)?;
            sets.clear();
            for i in 0..self.robots {
                let set = self.fields.footprint(&world.footprint_offsets(i));
                sets.extend([set; 4]);
            }
            self.fields
                .set_footprints(w, &sets)
                .map_err(backend_error)?;
            slot.fresh = false;
        }
        Ok(())
    }

    /// The step's field work for every world, after each began its step as `self.begun` says (the
    /// worlds that stepped have moved and injected): fields stepped, trails laid, every robot's
    /// colour sensors sensed.
    pub(crate) fn run(&mut self, slots: &mut [WorldSlot], dt: f32) -> Result<()> {
        let begun = std::mem::take(&mut self.begun);
        let result = self.run_with(slots, &begun, dt);
        self.begun = begun;
        result
    }

    fn run_with(&mut self, slots: &mut [WorldSlot], begun: &[Begun], dt: f32) -> Result<()> {
        let t0 = std::time::Instant::now();
        // New episodes that step now start from their CPU fields.
        self.load_fresh(slots, |w| begun[w] != Begun::Reset)?;
        // Worlds are not `Sync`: their trails are gathered (side by side, through `&mut`), then
        // queued.
        let trails: Vec<Option<&[TrailSegment]>> = (slots.par_iter_mut().zip(begun))
            .map(|(slot, b)| (*b != Begun::Reset).then(|| slot.world.trail_segments()))
            .collect();
        (self.fields)
            .queue_trails(|w| trails[w])
            .map_err(backend_error)?;
        let t1 = std::time::Instant::now();
        self.fields.step(dt).map_err(backend_error)?;
        let t2 = std::time::Instant::now();
        let robots = self.robots;
        (self.fields.centres_mut().par_chunks_mut(4 * robots.max(1)))
            .zip(slots.par_iter_mut())
            .for_each(|(centres, slot)| {
                for (i, c) in centres.chunks_exact_mut(4).enumerate() {
                    for (c, p) in c.iter_mut().zip(slot.world.sensor_centres(i)) {
                        *c = [p.x, p.y];
                    }
                }
            });
        let t3 = std::time::Instant::now();
        let sensed = self.fields.sense(&mut self.sums).map_err(backend_error);
        let t4 = std::time::Instant::now();
        for (k, (a, b)) in [(t0, t1), (t1, t2), (t2, t3), (t3, t4)]
            .into_iter()
            .enumerate()
        {
            self.seconds[1 + k] += (b - a).as_secs_f64();
        }
        sensed
    }

    /// World `w`'s footprint level sums of the last sensing, four per robot.
    pub(crate) fn sums_of(&self, w: usize) -> &[[u32; 3]] {
        let n = 4 * self.robots;
        &self.sums[w * n..(w + 1) * n]
    }

    /// Copies every world's grids back into its CPU fields (for what reads them there: patches,
    /// tasks written in Python, renders); a world built since the last load already has them there.
    pub(crate) fn sync(&self, slots: &mut [WorldSlot]) -> Result<()> {
        let all = self.fields.read_all().map_err(backend_error)?;
        for (slot, values) in slots.iter_mut().zip(&all) {
            if !slot.fresh {
                write_values(slot.world.pheromones_mut(), values);
            }
        }
        Ok(())
    }
}

impl GpuStage {
    /// World `w`'s pheromones with the batch's values (the world's own where it was built since the
    /// last load), for a render.
    pub(crate) fn pheromones_of(&self, w: usize, slot: &WorldSlot) -> Result<Vec<Pheromone>> {
        let values = if slot.fresh {
            Vec::new()
        } else {
            self.fields.read_world(w).map_err(backend_error)?
        };
        let mut copy: Vec<Pheromone> = (slot.world.pheromones().iter())
            .filter_map(|p| match &p.model {
                FieldModel::Grid(g) => {
                    let mut grid = GridField::new(*g.spec(), *g.params());
                    grid.values_mut().copy_from_slice(g.values());
                    Some(Pheromone {
                        name: p.name.clone(),
                        colour: p.colour,
                        model: FieldModel::Grid(grid),
                    })
                }
                FieldModel::Gaussian(_) => None,
            })
            .collect();
        if !values.is_empty() {
            write_values(&mut copy, &values);
        }
        Ok(copy)
    }
}

/// Overwrites the grid pheromones' values with `values` (one per grid pheromone, in order).
fn write_values(pheromones: &mut [Pheromone], values: &[Vec<f32>]) {
    let grids = pheromones.iter_mut().filter_map(|p| match &mut p.model {
        FieldModel::Grid(g) => Some(g),
        _ => None,
    });
    for (g, v) in grids.zip(values) {
        g.values_mut().copy_from_slice(v);
    }
}
