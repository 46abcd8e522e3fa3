//! The sensing state: the colour sensor model, the bumper rays, the neighbour index of the current
//! poses, every robot's sensor positions and its latest observation. Stages `index` and `sense`.
use super::{FieldSet, PARALLEL_ROBOTS, RobotSlot};
use crate::arena::Obstacles;
use crate::behaviour::Observation;
use crate::field::GridPrefetcher;
use crate::robot::Pose;
use crate::screen::ScreenSpec;
use crate::sensors::{
    BumperParams, BumperRays, ColourCalibration, ColourSensor, ColourSensorParams, NeighbourIndex,
    SENSOR_RADIUS, ScreenView, sensor_positions_facing,
};
use glam::Vec2;
use rayon::prelude::*;
use std::sync::Arc;

pub struct Sensing {
    sensor: ColourSensor,
    /// Each robot's own four sensors (`[sensor] per_robot`), or none: every robot reads through
    /// `sensor`.
    robot_sensors: Vec<RobotSensors>,
    /// Each robot's own colour gain and offset (`[individual]`), or none: every robot's counts as
    /// its sensors read them.
    sensor_gains: Vec<(f32, f32)>,
    bumper_params: BumperParams,
    bumper_rays: BumperRays,
    /// Robot radius, m (bumper rays start at the rim).
    radius: f32,
    /// Arena size, m (bumpers see its walls).
    arena: Vec2,
    neighbours: NeighbourIndex,
    /// Static obstacles the bumpers see (none by default).
    obstacles: Arc<Obstacles>,
    /// Scratch: robot positions for the neighbour index.
    positions: Vec<Vec2>,
    /// The four sensor positions of every robot at the indexed poses.
    sensor_points: Vec<[Vec2; 4]>,
    /// Every robot's heading vector at the indexed poses (one `sin_cos` for its colour sensors and
    /// bumpers, and for every later stage while its heading stays: [`Sensing::forward`]).
    forwards: Vec<Vec2>,
    /// The headings `forwards` were computed at.
    headings: Vec<f32>,
    /// Robots whose colour nobody reads ([`Sensing::set_colour_unread`]): their four sensors are not
    /// evaluated, only their noise drawn. Empty: every robot's are read.
    colour_unread: Vec<bool>,
    observations: Vec<Observation>,
}

impl Sensing {
    /// Robot `i`'s heading vector at `heading`: the one [`index`] computed while the heading is
    /// still the indexed one (the same bits as [`Pose::forward`]), else computed now.
    #[inline]
    pub fn forward(&self, i: usize, heading: f32) -> Vec2 {
        match (self.headings.get(i), self.forwards.get(i)) {
            (Some(h), Some(f)) if h.to_bits() == heading.to_bits() => *f,
            _ => Vec2::from_angle(heading),
        }
    }

    pub fn new(
        sensor: ColourSensor,
        bumper_params: BumperParams,
        radius: f32,
        arena: Vec2,
        robots: usize,
    ) -> Self {
        Sensing {
            sensor,
            robot_sensors: Vec::new(),
            sensor_gains: Vec::new(),
            bumper_rays: BumperRays::new(&bumper_params),
            bumper_params,
            radius,
            arena,
            neighbours: NeighbourIndex::default(),
            obstacles: Arc::default(),
            positions: Vec::new(),
            sensor_points: Vec::new(),
            forwards: Vec::new(),
            headings: Vec::new(),
            colour_unread: Vec::new(),
            observations: vec![Observation::default(); robots],
        }
    }
    /// The colour sensor model shared by all robots.
    pub fn sensor(&self) -> &ColourSensor {
        &self.sensor
    }
    /// Robot `i`'s own sensors, if the robots have their own ([`Sensing::set_robot_sensors`]).
    pub fn robot_sensors(&self, i: usize) -> Option<&RobotSensors> {
        self.robot_sensors.get(i)
    }
    /// Gives each robot its own four sensors (one entry per robot, in order).
    pub fn set_robot_sensors(&mut self, sensors: Vec<RobotSensors>) {
        self.robot_sensors = sensors;
    }
    /// Robot `i`'s own colour gain and offset (`[individual]`), if the robots have their own.
    pub fn sensor_gain(&self, i: usize) -> Option<(f32, f32)> {
        self.sensor_gains.get(i).copied()
    }
    /// Gives each robot its own colour gain and offset on the counts (one entry per robot).
    pub fn set_sensor_gains(&mut self, gains: Vec<(f32, f32)>) {
        self.sensor_gains = gains;
    }
    /// The arena's static obstacles (what the bumpers see besides walls and robots).
    pub fn obstacles(&self) -> &Arc<Obstacles> {
        &self.obstacles
    }
    pub fn set_obstacles(&mut self, obstacles: Arc<Obstacles>) {
        self.obstacles = obstacles;
    }
    /// The neighbour index of the last indexed poses.
    pub fn neighbours(&self) -> &NeighbourIndex {
        &self.neighbours
    }
    /// Robot `i`'s four colour sensors' centres at the poses last indexed.
    pub fn sensor_centres(&self, i: usize) -> [Vec2; 4] {
        self.sensor_points[i]
    }
    /// Where robot `i`'s colour sensors sample the screen, from each sensor's centre (the same for
    /// its four: [`ColourSensor::sample_points`] adds a centre to them): what
    /// [`super::World::sense_from_sums`] wants the level sums over.
    pub fn footprint_offsets(&self, i: usize) -> [Vec2; crate::sensors::RING_POINTS + 1] {
        let sampler = self
            .robot_sensors
            .get(i)
            .map_or(&self.sensor, |own| &own.truth[0]);
        sampler.sample_points(Vec2::ZERO)
    }
    /// Marks the robots whose colour readings nobody reads (one entry per robot; empty: none). Their
    /// sensors are not evaluated and read 0, but their sensor noise is still drawn, so every random
    /// stream, and so every other reading and every pose, stays as if they had been read. A robot
    /// with its own sensor models (`[sensor] per_robot`) is always read.
    pub fn set_colour_unread(&mut self, unread: Vec<bool>) {
        self.colour_unread = unread;
    }
    /// Robot `i`'s colour is read again (no effect if it was).
    pub fn keep_colour_read(&mut self, i: usize) {
        if let Some(u) = self.colour_unread.get_mut(i) {
            *u = false;
        }
    }
    /// What each robot sensed last.
    pub fn observations(&self) -> &[Observation] {
        &self.observations
    }
    /// The observations, for a host whose robots report their own readings (real sensors).
    pub fn observations_mut(&mut self) -> &mut [Observation] {
        &mut self.observations
    }
}

/// Stage `index`: the bumpers' neighbour index and every robot's sensor positions, from `poses`.
///
/// Reads `poses`; writes the neighbour index and the sensor positions.
pub fn index(sensing: &mut Sensing, poses: &[Pose]) {
    let cell = 2.0 * sensing.radius + sensing.bumper_params.range;
    sensing.positions.clear();
    sensing.positions.extend(poses.iter().map(|p| p.pos));
    sensing
        .neighbours
        .rebuild(sensing.arena, cell, &sensing.positions);
    // Sensor positions once per robot: sensing reads robot i's, prefetching robot i + 1's.
    sensing.forwards.clear();
    sensing.forwards.extend(poses.iter().map(Pose::forward));
    sensing.headings.clear();
    sensing.headings.extend(poses.iter().map(|p| p.heading));
    sensing.sensor_points.clear();
    sensing.sensor_points.extend(
        poses
            .iter()
            .zip(&sensing.forwards)
            .map(|(p, f)| sensor_positions_facing(p, *f, SENSOR_RADIUS)),
    );
}

/// Stage `sense`: every robot's observation at `time` from the screen that `fields` draw, at the poses
/// last given to [`index`] (which must be `poses`).
///
/// Reads the pheromones, `screen`, `poses` and each slot's last command; writes the frozen Gaussian
/// sources, each slot's random stream (sensor noise) and the observations.
pub fn sense(
    sensing: &mut Sensing,
    fields: &mut FieldSet,
    screen: &ScreenSpec,
    poses: &[Pose],
    slots: &mut [RobotSlot],
    time: f32,
) {
    let sets = SenseSets {
        fields,
        screen,
        poses,
        slots,
        time,
    };
    sense_with(sensing, sets, None);
}

/// The data sets stage [`sense`] reads and writes besides the sensing state, at `time`.
pub(super) struct SenseSets<'a> {
    pub(super) fields: &'a mut FieldSet,
    pub(super) screen: &'a ScreenSpec,
    pub(super) poses: &'a [Pose],
    pub(super) slots: &'a mut [RobotSlot],
    pub(super) time: f32,
}

/// Stage [`sense`], with the colour sensors' footprint level sums computed here (`None`) or `given`
/// (four per robot, in robot then sensor order, over [`Sensing::footprint_offsets`] from
/// [`Sensing::sensor_centres`]), e.g. from a GPU that holds the grid pheromones: the same
/// observations and random draws as on a screen with those sums.
///
/// # Panics
/// If `given` does not hold four entries per robot.
pub(super) fn sense_with(sensing: &mut Sensing, sets: SenseSets, given: Option<&[[u32; 3]]>) {
    let SenseSets {
        fields,
        screen,
        poses,
        slots,
        time,
    } = sets;
    if let Some(sums) = given {
        assert_eq!(sums.len(), 4 * slots.len(), "four footprint sums per robot");
    }
    fields.freeze();
    let (sensor_points, forwards) = (&sensing.sensor_points, &sensing.forwards);
    let (pheromones, frozen) = (fields.pheromones(), fields.frozen());
    let (sensor, neighbours, bumper) = (&sensing.sensor, &sensing.neighbours, &sensing.bumper_rays);
    let robot_sensors = &sensing.robot_sensors;
    let sensor_gains = &sensing.sensor_gains;
    let colour_unread = &sensing.colour_unread;
    let (radius, arena) = (sensing.radius, sensing.arena);
    let obstacles = &*sensing.obstacles;
    let view = ScreenView {
        pheromones,
        frozen,
        screen,
        printed: obstacles.printed(),
    };
    let prefetcher = GridPrefetcher::new(pheromones);
    let sense = |(i, (slot, obs)): (usize, (&mut RobotSlot, &mut Observation))| {
        // The grid cells under the next robot's sensors are scattered over large fields: ask for
        // them now so that their cache misses overlap with this robot's work.
        if let (Some(prefetcher), Some(next)) = (&prefetcher, sensor_points.get(i + 1)) {
            prefetcher.prefetch(next);
        }
        let mut o = Observation {
            time,
            last_command: slot.command,
            ..Observation::default()
        };
        let given = given.map(|g| [g[4 * i], g[4 * i + 1], g[4 * i + 2], g[4 * i + 3]]);
        let unread =
            robot_sensors.get(i).is_none() && colour_unread.get(i).copied().unwrap_or(false);
        match robot_sensors.get(i) {
            Some(own) => {
                // The four footprints in one batched pass (they are all the drawn `[sensor]`
                // section's), then each sensor's own model in order: the same draws as `read_all`'s.
                let sums = given
                    .unwrap_or_else(|| own.truth[0].footprint_sums_in(&view, &sensor_points[i]));
                for (k, sum) in sums.into_iter().enumerate() {
                    let c = own.truth[k].counts_of_sum(sum, &mut slot.rng);
                    o.counts[k] = c;
                    o.intensity[k] = own.inverse[k].intensity(c);
                }
            }
            None if unread => sensor.draw_read_noise(&mut slot.rng),
            None => {
                (o.counts, o.intensity) = match &given {
                    Some(sums) => sensor.read_robot_from_sums(sums, &mut slot.rng),
                    None => sensor.read_robot(&view, &sensor_points[i], &mut slot.rng),
                };
            }
        }
        // A robot's own gain and offset act on the counts its sensors deliver; its intensities
        // then read them through the calibrated (nominal) inverse, as the rig's robot would.
        if let Some(&(gain, offset)) = sensor_gains.get(i).filter(|_| !unread) {
            crate::scenario::individual::apply_sensor_gain(&mut o.counts, gain, offset);
            o.intensity = match robot_sensors.get(i) {
                Some(own) => std::array::from_fn(|k| own.inverse[k].intensity(o.counts[k])),
                None => sensor.intensities(&o.counts),
            };
        }
        o.bumpers =
            neighbours.bumpers_facing(i, poses, forwards[i], radius, arena, bumper, obstacles);
        *obs = o;
    };
    if slots.len() >= PARALLEL_ROBOTS {
        slots
            .par_iter_mut()
            .zip(sensing.observations.par_iter_mut())
            .enumerate()
            .for_each(sense);
    } else {
        slots
            .iter_mut()
            .zip(sensing.observations.iter_mut())
            .enumerate()
            .for_each(sense);
    }
}

/// One robot's own four colour sensors (simulator order): the model its counts are drawn from, and
/// the calibrated inverse its intensities are read through (the calibration file's, as on the rig;
/// they differ only by a world's `[randomize]` draws).
#[derive(Clone, Debug)]
pub struct RobotSensors {
    pub truth: [ColourSensor; 4],
    pub inverse: [ColourSensor; 4],
}

/// Every robot's own sensors from `calibration` (robot i is the file's robot with radio address
/// `radio[i]`). `drawn` is the world's `[sensor]` section after its `[randomize]` draws, `base` the
/// scenario's: their gain ratio and crosstalk difference go on top of every fitted sensor. `file`
/// names the file in errors.
pub fn per_robot_sensors(
    calibration: &ColourCalibration,
    radio: &[u8],
    drawn: &ColourSensorParams,
    base: &ColourSensorParams,
    file: &str,
) -> crate::error::Result<Vec<RobotSensors>> {
    let gain_factor = if base.gain > 0.0 {
        drawn.gain / base.gain
    } else {
        1.0
    };
    let offset: [[f32; 3]; 3] = std::array::from_fn(|c| {
        std::array::from_fn(|k| drawn.crosstalk[c][k] - base.crosstalk[c][k])
    });
    let ids: Vec<u8> = calibration.robots.iter().map(|r| r.radio_id).collect();
    radio
        .iter()
        .enumerate()
        .map(|(i, id)| {
            let robot = calibration.robot(*id).ok_or_else(|| {
                crate::error::SimError::invalid(
                    "rig.colour_calibration",
                    format!("{file:?}"),
                    format!(
                        "[sensor] per_robot: robot {i} (radio address {id}) is not in the file, \
                         which holds radio addresses {ids:?} ({} robots for the scenario's {})",
                        ids.len(),
                        radio.len()
                    ),
                )
            })?;
            Ok(RobotSensors {
                truth: robot.sensors.map(|f| f.sensor(drawn, gain_factor, &offset)),
                inverse: robot.sensors.map(|f| f.sensor(base, 1.0, &[[0.0; 3]; 3])),
            })
        })
        .collect()
}
