//! Sensing on the GPU from query points: every sensor of every world in one dispatch, only the
//! level sums read back.
use super::{GpuScreen, POINTS_PER_SENSOR, ScreenScene, SensorQuery, Uni, groups};
use crate::{GpuGrids, Result, storage};
use colcos_sim::screen::ScreenSpec;

impl GpuScreen {
    /// Sums of the 8-bit screen levels (r, g, b) over each query's points; the mean level that
    /// [`colcos_sim::sensors::ColourSensor::screen_levels`] returns is `sum / POINTS_PER_SENSOR`
    /// (see [`mean_levels`]). One dispatch for every sensor of every world; only the sums come back.
    pub fn sense(
        &self,
        grids: Option<&GpuGrids>,
        scene: &ScreenScene,
        screen: &ScreenSpec,
        queries: &[SensorQuery],
    ) -> Result<Vec<[u32; 3]>> {
        if queries.is_empty() {
            return Ok(Vec::new());
        }
        let n = queries.len();
        let points: Vec<[f32; 2]> = queries
            .iter()
            .flat_map(|q| q.points.iter().map(|p| [p.x, p.y]))
            .collect();
        let worlds: Vec<u32> = queries.iter().map(|q| q.world).collect();
        if worlds.iter().any(|&w| w as usize >= scene.worlds.len()) {
            return Err(crate::GpuError::Invalid(
                "sensor query for a world the scene does not have".into(),
            ));
        }
        let out = self.ctx.scoped("allocating the sensor sums", || {
            storage(
                &self.ctx,
                "colcos sensor sums",
                n as u64 * 12,
                wgpu::BufferUsages::empty(),
            )
        })?;
        let (gx, gy) = groups(n, 64);
        let spec = grids.map(|g| *g.spec());
        let ps = screen.pixel_size();
        let uni = Uni {
            width: POINTS_PER_SENSOR as u32,
            nx: spec.map_or(1, |s| s.nx as u32),
            ny: spec.map_or(1, |s| s.ny as u32),
            groups_x: gx,
            count: n as u32,
            cell: spec.map_or(1.0, |s| s.cell),
            ps_x: ps.x,
            ps_y: ps.y,
            res_x: screen.resolution[0],
            res_y: screen.resolution[1],
            ..Default::default()
        };
        self.dispatch(
            grids,
            scene,
            uni,
            &self.sense,
            &out,
            bytemuck::cast_slice(&points),
            bytemuck::cast_slice(&worlds),
            (gx, gy),
        )?;
        let bytes = self.ctx.read_buffer(&out, 0, n as u64 * 12)?;
        let sums: &[u32] = bytemuck::cast_slice(&bytes);
        Ok(sums.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect())
    }
}

/// Mean levels from the sums of [`GpuScreen::sense`], as the CPU computes them.
pub fn mean_levels(sum: [u32; 3]) -> [f32; 3] {
    sum.map(|s| s as f32 / POINTS_PER_SENSOR as f32)
}
