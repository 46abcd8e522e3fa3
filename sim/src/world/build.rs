//! Building a world from a scenario: fields with their static maps, robots, emitters.
use super::{Deposit, Emitter, RobotSlot, World};
use crate::behaviour::{Observation, WheelCommand, registry};
use crate::error::Result;
use crate::field::{
    FieldModel, GaussianField, GaussianSource, GridField, GridParams, GridSpec, Pheromone,
    image_map, polyline_map,
};
use crate::rng;
use crate::robot::{ArenaPhysics, DriveState, Pose};
use crate::scenario::{EmitWhen, MapSpec, ModelKind, PheromoneSpec, Scenario};
use crate::sensors::{BumperRays, ColourSensor, NeighbourIndex};
use crate::tracker::Tracker;
use glam::Vec2;

/// Random streams of a world: 0 placement, 1 tracker, 2.. one per robot.
const STREAM_PLACEMENT: u64 = 0;
const STREAM_TRACKER: u64 = 1;
const STREAM_ROBOT0: u64 = 2;

impl World {
    /// A world for `scenario`, world index 0.
    pub fn new(scenario: &Scenario) -> Result<World> {
        Self::with_index(scenario, 0)
    }

    /// A world for `scenario` whose random streams derive from `(seed, world_index)`: the worlds of a
    /// batch differ, and none depends on how many threads step them.
    pub fn with_index(scenario: &Scenario, world_index: u64) -> Result<World> {
        let spec = &scenario.spec;
        let arena = scenario.arena_size();
        let grid = GridSpec::covering(arena, spec.field.cell);
        let mut pheromones = spec
            .pheromones
            .iter()
            .enumerate()
            .map(|(i, p)| build_pheromone(scenario, i, p, grid))
            .collect::<Result<Vec<_>>>()?;

        let mut placement_rng = rng::stream(spec.seed, world_index, STREAM_PLACEMENT);
        let mut poses: Vec<Pose> = Vec::with_capacity(scenario.robot_count());
        let mut robots = Vec::with_capacity(scenario.robot_count());
        let mut deposits = Vec::new();
        let mut emitters = Vec::new();
        for (g, group) in spec.robots.iter().enumerate() {
            let key = format!("robots[{g}]");
            let placed = super::placement::place_group(
                group,
                &key,
                arena,
                spec.robot.radius,
                &poses,
                &mut placement_rng,
            )?;
            for pose in placed {
                let index = poses.len();
                poses.push(pose);
                robots.push(RobotSlot {
                    group: g,
                    behaviour: registry::build(&group.behaviour, &group.params, &key)?,
                    rng: rng::stream(spec.seed, world_index, STREAM_ROBOT0 + index as u64),
                    drive: DriveState::default(),
                    command: WheelCommand::STOP,
                });
                for d in &group.deposits {
                    let pheromone = scenario.pheromone_index(&d.pheromone).expect("validated");
                    deposits.push(Deposit {
                        robot: index,
                        pheromone,
                        kernel: d.kernel,
                        rate: d.rate,
                    });
                }
                for e in &group.emits {
                    let pheromone = scenario.pheromone_index(&e.pheromone).expect("validated");
                    let FieldModel::Gaussian(field) = &mut pheromones[pheromone].model else {
                        unreachable!("validated")
                    };
                    let (start, near) = match &e.when {
                        EmitWhen::Follow => (0.0, None),
                        EmitWhen::Near { role, distance } => (
                            f32::INFINITY,
                            Some((robots_with_role(scenario, role, index), *distance)),
                        ),
                    };
                    field.sources.push(GaussianSource {
                        k: e.k,
                        sigma_x: e.sigma[0],
                        sigma_y: e.sigma[1],
                        rho: e.rho,
                        evaporation: e.evaporation,
                        centre: pose.pos,
                        start,
                    });
                    emitters.push(Emitter {
                        robot: index,
                        pheromone,
                        source: field.sources.len() - 1,
                        near,
                    });
                }
            }
        }
        let physics = ArenaPhysics::with_backend(arena, &spec.robot, &poses, spec.physics);
        let mut tracker = Tracker::new(spec.tracker, poses.len());
        let mut tracker_rng = rng::stream(spec.seed, world_index, STREAM_TRACKER);
        let tracked = tracker.update(0.0, &poses, &mut tracker_rng).to_vec();
        let mut world = World {
            scenario: scenario.clone(),
            time: 0.0,
            tick: 0,
            dt: spec.dt,
            arena,
            robot_params: spec.robot,
            bumper_params: spec.bumper,
            bumper_rays: BumperRays::new(&spec.bumper),
            screen: spec.screen,
            inject_at: spec.field.inject_at,
            pheromones,
            physics,
            observations: vec![Observation::default(); robots.len()],
            last_injection: vec![None; robots.len()],
            segments: Vec::new(),
            band_segments: Vec::new(),
            robots,
            tracker,
            tracker_rng,
            tracked,
            neighbours: NeighbourIndex::default(),
            sensor: ColourSensor::new(spec.sensor),
            deposits,
            emitters,
            velocities: Vec::new(),
            positions: Vec::new(),
            sensor_points: Vec::new(),
            frozen: Default::default(),
            field_backend: None,
        };
        world.inject();
        world.observe();
        Ok(world)
    }
}

/// Indices of every robot of role `role` other than `me` (groups are numbered contiguously).
fn robots_with_role(scenario: &Scenario, role: &str, me: usize) -> Vec<usize> {
    let mut first = 0;
    let mut out = Vec::new();
    for g in &scenario.spec.robots {
        if g.role == role {
            out.extend((first..first + g.count).filter(|&i| i != me));
        }
        first += g.count;
    }
    out
}

fn build_pheromone(
    scenario: &Scenario,
    index: usize,
    p: &PheromoneSpec,
    grid: GridSpec,
) -> Result<Pheromone> {
    let model = match p.model {
        ModelKind::Grid => {
            let params = GridParams {
                evaporation: p.evaporation.unwrap_or(f32::INFINITY),
                diffusion: p.diffusion,
                scheme: p.scheme,
                wind: Vec2::from(p.wind),
            };
            let mut field = GridField::new(grid, params);
            if !p.maps.is_empty() {
                let mut j = vec![0.0f32; grid.len()];
                for (m, map) in p.maps.iter().enumerate() {
                    let layer = build_map(
                        scenario,
                        &format!("pheromones[{index}].maps[{m}]"),
                        map,
                        &grid,
                    )?;
                    j.iter_mut().zip(layer).for_each(|(a, b)| *a += b);
                }
                field.set_static_injection(j);
            }
            FieldModel::Grid(field)
        }
        ModelKind::Gaussian => FieldModel::Gaussian(GaussianField {
            sources: p
                .sources
                .iter()
                .map(|s| GaussianSource {
                    k: s.k,
                    sigma_x: s.sigma[0],
                    sigma_y: s.sigma[1],
                    rho: s.rho,
                    evaporation: s.evaporation,
                    centre: Vec2::from(s.centre),
                    start: s.start,
                })
                .collect(),
            time: 0.0,
        }),
    };
    Ok(Pheromone {
        name: p.name.clone(),
        colour: p.colour,
        model,
    })
}

fn build_map(scenario: &Scenario, _key: &str, map: &MapSpec, grid: &GridSpec) -> Result<Vec<f32>> {
    if let Some(points) = &map.polyline {
        let pts: Vec<Vec2> = points.iter().map(|p| Vec2::from(*p)).collect();
        return Ok(polyline_map(grid, &pts, map.width.unwrap_or(0.0), map.rate));
    }
    let path = scenario
        .base_dir
        .join(map.image.as_deref().unwrap_or_default());
    let channel = match map.channel.as_deref() {
        Some("r") => Some(0),
        Some("g") => Some(1),
        Some("b") => Some(2),
        _ => None,
    };
    image_map(grid, &path, channel, map.rate)
}

impl World {
    /// Replaces the behaviour of robot `i` (e.g. with a learned policy).
    pub fn set_behaviour(&mut self, i: usize, behaviour: Box<dyn crate::behaviour::Behaviour>) {
        self.robots[i].behaviour = behaviour;
    }

    /// A fresh neighbour index (used by tests that probe bumpers directly).
    pub fn neighbour_index(&self) -> &NeighbourIndex {
        &self.neighbours
    }
}
