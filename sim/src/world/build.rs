//! Building a world from a scenario: fields with their static maps, robots, emitters; and the same
//! parts without bodies or a tracker model, for a host whose robots and tracker are real.
use super::inject::{Deposit, EmitRule, Emitter};
use super::{FieldSet, Injection, RobotSet, RobotSlot, Sensing, Tracking, World};
use crate::behaviour::WheelCommand;
use crate::error::Result;
use crate::field::{
    FieldModel, GaussianField, GaussianSource, GridField, GridParams, GridSpec, Pheromone,
    image_map, polyline_map,
};
use crate::rng::{self, Stream};
use crate::robot::{Actuation, ArenaPhysics, DriveState, Pose};
use crate::scenario::{
    EmitWhen, MapSpec, ModelKind, PheromoneSpec, Scenario, ScenarioSpec, placement,
};
use crate::sensors::ColourSensor;
use crate::tracker::Tracker;
use glam::Vec2;

/// Every data set of a world but its bodies and tracker model: the fields, the robots' behaviours and
/// random streams, the injection rules and the sensing state, with the robots' initial poses. A host
/// whose arena and tracker are real steps these with the stages.
pub struct WorldParts {
    pub fields: FieldSet,
    pub slots: Vec<RobotSlot>,
    pub injection: Injection,
    pub sensing: Sensing,
    /// Where the scenario places each robot at the start.
    pub poses: Vec<Pose>,
}

impl World {
    /// A world for `scenario`, world index 0.
    pub fn new(scenario: &Scenario) -> Result<World> {
        Self::with_index(scenario, 0)
    }

    /// A world for `scenario` whose random streams derive from `(seed, world_index)`: the worlds of a
    /// batch differ, and none depends on how many threads step them.
    pub fn with_index(scenario: &Scenario, world_index: u64) -> Result<World> {
        // Domain randomisation: this world's own draw of the `[randomize]` ranges.
        let base_sensor = scenario.spec.sensor;
        let drawn;
        let mut rng = None;
        let scenario = if scenario.spec.randomize.is_default() {
            scenario
        } else {
            let mut sc = scenario.clone();
            let rng = rng.insert(rng::stream_of(sc.spec.seed, world_index, Stream::Randomize));
            let s = &mut sc.spec;
            let parts = crate::scenario::Randomized {
                tracker: &mut s.tracker,
                sensor: &mut s.sensor,
                robot: &mut s.robot,
            };
            scenario.spec.randomize.apply(parts, rng);
            drawn = sc;
            &drawn
        };
        let spec = &scenario.spec;
        let arena = scenario.arena_size();
        let mut parts = WorldParts::build(scenario, world_index)?;
        if spec.sensor.per_robot {
            let sensors = robot_sensors(scenario, &base_sensor, parts.poses.len())?;
            parts.sensing.set_robot_sensors(sensors);
        }
        // Robots that differ (`[individual]`), then `[randomize]`'s draws around each one's values.
        let n = parts.poses.len();
        let mut each = crate::scenario::individual::resolve(scenario, n)?;
        if let Some(rng) = rng.as_mut()
            && spec.randomize.draws_per_robot()
        {
            let each = each.get_or_insert_with(|| vec![Default::default(); n]);
            spec.randomize.apply_each(each, spec.robot.motor_lag, rng);
        }
        if let Some(each) = &each {
            individualise(&mut parts, each, spec);
        }
        let mut physics =
            ArenaPhysics::with_backend(arena, &spec.robot, &parts.poses, spec.physics);
        physics.set_obstacles(parts.sensing.obstacles().clone());
        let tracking = Tracking::new(
            Tracker::new(spec.tracker, parts.poses.len()),
            rng::stream_of(spec.seed, world_index, Stream::Tracker),
            &parts.poses,
        );
        let mut world = World {
            scenario: scenario.clone(),
            time: 0.0,
            tick: 0,
            dt: spec.dt,
            arena,
            screen: spec.screen,
            fields: parts.fields,
            robots: RobotSet::new(spec.robot, physics, parts.slots),
            tracking,
            injection: parts.injection,
            sensing: parts.sensing,
        };
        super::stages::inject(
            &mut world.injection,
            &mut world.fields,
            world.robots.poses(),
            world.tracking.tracked(),
            world.dt,
        );
        world.observe();
        Ok(world)
    }
}

impl WorldParts {
    /// The parts of world `world_index` of `scenario` (random streams as [`World::with_index`]'s).
    pub fn build(scenario: &Scenario, world_index: u64) -> Result<WorldParts> {
        let spec = &scenario.spec;
        let arena = scenario.arena_size();
        let grid = GridSpec::covering(arena, spec.field.cell);
        let mut pheromones = spec
            .pheromones
            .iter()
            .enumerate()
            .map(|(i, p)| build_pheromone(scenario, i, p, grid))
            .collect::<Result<Vec<_>>>()?;

        let mut placement_rng = rng::stream_of(spec.seed, world_index, Stream::Placement);
        // Built once: placement keeps robots off them, then the bumpers and physics see them.
        let obstacles = std::sync::Arc::new(scenario.obstacles()?);
        let poses: Vec<Pose> = placement::place(scenario, &obstacles, &mut placement_rng)?;
        let mut slots = Vec::with_capacity(poses.len());
        let mut deposits = Vec::new();
        let mut emitters = Vec::new();
        for (g, group) in spec.robots.iter().enumerate() {
            let key = format!("robots[{g}]");
            let first = slots.len();
            for (index, &pose) in poses.iter().enumerate().skip(first).take(group.count) {
                slots.push(RobotSlot {
                    group: g,
                    behaviour: group.build_behaviour(&spec.robot, &key)?,
                    rng: rng::stream_of(spec.seed, world_index, Stream::Robot(index)),
                    drive: DriveState::default(),
                    command: WheelCommand::STOP,
                    actuation: None,
                });
                for d in &group.deposits {
                    let pheromone = scenario.pheromone_index(&d.pheromone).expect("validated");
                    deposits.push(Deposit {
                        robot: index,
                        pheromone,
                        kernel: d.kernel,
                        rate: d.rate,
                        action: None,
                    });
                }
                // An agent's chosen trails right after the scripted ones: a constant action lays
                // what a `deposits` rule in their place would, in the same order.
                for (k, d) in group.deposit_actions.iter().enumerate() {
                    let pheromone = scenario.pheromone_index(&d.pheromone).expect("validated");
                    deposits.push(Deposit {
                        robot: index,
                        pheromone,
                        kernel: d.kernel,
                        rate: d.max_rate,
                        action: Some(k),
                    });
                }
                let mut switch = group.deposit_actions.len();
                for e in &group.emits {
                    let pheromone = scenario.pheromone_index(&e.pheromone).expect("validated");
                    let FieldModel::Gaussian(field) = &mut pheromones[pheromone].model else {
                        unreachable!("validated")
                    };
                    let (start, rule) = match &e.when {
                        EmitWhen::Follow => (0.0, EmitRule::Follow),
                        EmitWhen::Near { role, distance } => (
                            f32::INFINITY,
                            EmitRule::Near(robots_with_role(scenario, role, index), *distance),
                        ),
                        EmitWhen::Action => {
                            switch += 1;
                            (f32::INFINITY, EmitRule::Action(switch - 1))
                        }
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
                        rule,
                    });
                }
            }
        }
        let count = slots.len();
        let mut sensing = Sensing::new(
            ColourSensor::new(spec.sensor),
            spec.bumper,
            spec.robot.radius,
            arena,
            count,
        );
        sensing.set_obstacles(obstacles);
        Ok(WorldParts {
            fields: FieldSet::new(pheromones),
            slots,
            injection: Injection::new(spec.field.inject_at, deposits, emitters, count),
            sensing,
            poses,
        })
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
                if p.preload {
                    // Validation allows it only with evaporation set and no diffusion or wind.
                    field.fill_steady_state();
                }
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
    let (image, channel, rate) = match map {
        MapSpec::Polyline {
            polyline,
            width,
            rate,
        } => {
            let pts: Vec<Vec2> = polyline.iter().map(|p| Vec2::from(*p)).collect();
            return Ok(polyline_map(grid, &pts, *width, *rate));
        }
        MapSpec::Image {
            image,
            channel,
            rate,
        } => (image, channel, *rate),
    };
    let path = scenario.base_dir.join(image);
    use crate::channel::{Channel, ImageChannel};
    // Reading the file refused alpha for maps; luma is the default.
    let channel = match channel {
        Some(ImageChannel::R) => Some(Channel::R),
        Some(ImageChannel::G) => Some(Channel::G),
        Some(ImageChannel::B) => Some(Channel::B),
        Some(ImageChannel::A | ImageChannel::Luma) | None => None,
    };
    image_map(grid, &path, channel, rate)
}

/// `[sensor] per_robot`: every robot's own sensors from the file `[rig] colour_calibration` names
/// (relative to the scenario's directory), with the world's `[randomize]` draws (`scenario`'s
/// `[sensor]` against `base`) on top.
fn robot_sensors(
    scenario: &Scenario,
    base: &crate::sensors::ColourSensorParams,
    robots: usize,
) -> Result<Vec<super::RobotSensors>> {
    let spec = &scenario.spec;
    let Some(file) = &spec.rig.colour_calibration else {
        return Err(crate::error::SimError::invalid(
            "sensor.per_robot",
            true,
            "needs the file of the robots' fitted sensors in [rig] colour_calibration",
        ));
    };
    let calibration = crate::sensors::ColourCalibration::load(&scenario.base_dir.join(file))
        .map_err(|e| {
            crate::error::SimError::invalid(
                "rig.colour_calibration",
                format!("{file:?}"),
                e.to_string(),
            )
        })?;
    let radio = spec.rig.radio_addresses(robots)?;
    super::sensing::per_robot_sensors(&calibration, &radio, &spec.sensor, base, file)
}

/// Gives every robot that differs from the nominal model its own actuation and sensor gain.
fn individualise(
    parts: &mut WorldParts,
    each: &[crate::scenario::Individual],
    spec: &ScenarioSpec,
) {
    for (slot, own) in parts.slots.iter_mut().zip(each) {
        if !own.drives_nominally() {
            slot.actuation = Some(Actuation::new(
                own.wheel_scale,
                own.motor_lag.unwrap_or(spec.robot.motor_lag),
                own.latency,
                spec.dt,
            ));
        }
    }
    if each.iter().any(|e| !e.senses_nominally()) {
        let gains = each
            .iter()
            .map(|e| (e.sensor_gain, e.sensor_offset))
            .collect();
        parts.sensing.set_sensor_gains(gains);
    }
}
