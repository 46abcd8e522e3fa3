//! Scenarios built in code rather than parsed from TOML: [`ScenarioBuilder`] and chainable
//! constructors of its parts ([`PheromoneSpec::grid`], [`RobotGroupSpec::new`], ...). Everything the
//! builder does not set keeps the value a TOML file that omits the key gets, and [`ScenarioBuilder::build`]
//! validates as [`Scenario::from_toml_str`] does.
//!
//! ```
//! use colcos_sim::field::Kernel;
//! use colcos_sim::scenario::{PheromoneSpec, RobotGroupSpec, ScenarioBuilder};
//!
//! let scenario = ScenarioBuilder::new()
//!     .duration(5.0)
//!     .arena([1.0, 0.6])
//!     .pheromone(PheromoneSpec::grid("red", [255.0, 0.0, 0.0]).with_evaporation(20.0))
//!     .robots(
//!         RobotGroupSpec::new(10, "follow")
//!             .with_param("channel", "r")
//!             .with_deposit("red", Kernel::Disc { radius: 0.01 }, 3.0),
//!     )
//!     .build()
//!     .unwrap();
//! assert_eq!(scenario.robot_count(), 10);
//! ```
use super::{
    DepositActionSpec, DepositSpec, EmitSpec, EmitWhen, MapSpec, ModelKind, PheromoneSpec,
    Placement, RobotGroupSpec, Scenario, ScenarioSpec, SourceSpec, parse_spec,
};
use crate::error::Result;
use crate::field::{BackendChoice, Kernel};
use crate::robot::PhysicsBackend;
use std::path::PathBuf;

/// A [`Scenario`] put together in code. Starts from the defaults of a scenario file with only
/// `duration = 10.0` in it.
#[derive(Clone, Debug)]
pub struct ScenarioBuilder {
    spec: ScenarioSpec,
    base_dir: PathBuf,
}

impl Default for ScenarioBuilder {
    fn default() -> Self {
        Self::new()
    }
}

impl ScenarioBuilder {
    pub fn new() -> Self {
        // Parsed rather than written out, so the defaults are the TOML path's by construction.
        let spec = parse_spec("duration = 10.0").expect("a duration is a complete scenario");
        ScenarioBuilder {
            spec,
            base_dir: PathBuf::from("."),
        }
    }

    pub fn name(mut self, name: impl Into<String>) -> Self {
        self.spec.name = name.into();
        self
    }

    /// Length of a run, s.
    pub fn duration(mut self, seconds: f32) -> Self {
        self.spec.duration = seconds;
        self
    }

    /// Time step, s.
    pub fn dt(mut self, seconds: f32) -> Self {
        self.spec.dt = seconds;
        self
    }

    pub fn seed(mut self, seed: u64) -> Self {
        self.spec.seed = seed;
        self
    }

    /// The screen's resolution (pixels) and size (m); the arena is the screen unless [`Self::arena`].
    pub fn screen(mut self, resolution: [u32; 2], size: [f32; 2]) -> Self {
        self.spec.screen.resolution = resolution;
        self.spec.screen.size = size;
        self
    }

    /// The walled arena's width and height, m.
    pub fn arena(mut self, size: [f32; 2]) -> Self {
        self.spec.arena.size = Some(size);
        self
    }

    /// Cell side of the grid shared by all grid pheromones, m.
    pub fn cell(mut self, cell: f32) -> Self {
        self.spec.field.cell = cell;
        self
    }

    pub fn field_backend(mut self, backend: BackendChoice) -> Self {
        self.spec.field.backend = backend;
        self
    }

    pub fn physics(mut self, physics: PhysicsBackend) -> Self {
        self.spec.physics = physics;
        self
    }

    /// Seconds between GIF frames; 0: no GIF.
    pub fn gif_interval(mut self, seconds: f32) -> Self {
        self.spec.output.gif_interval = seconds;
        self
    }

    /// Adds a pheromone (in screen order: its index is the number added before it).
    pub fn pheromone(mut self, pheromone: PheromoneSpec) -> Self {
        self.spec.pheromones.push(pheromone);
        self
    }

    /// Adds a group of robots.
    pub fn robots(mut self, group: RobotGroupSpec) -> Self {
        self.spec.robots.push(group);
        self
    }

    /// Any other part of the spec (robot body, sensors, tracker, ...).
    pub fn with(mut self, edit: impl FnOnce(&mut ScenarioSpec)) -> Self {
        edit(&mut self.spec);
        self
    }

    /// Directory that relative paths (map images) are resolved against; default `.`.
    pub fn base_dir(mut self, dir: impl Into<PathBuf>) -> Self {
        self.base_dir = dir.into();
        self
    }

    /// The spec as it stands, not yet validated.
    pub fn spec(self) -> ScenarioSpec {
        self.spec
    }

    /// The validated scenario; errors name the key path as for a scenario file.
    pub fn build(self) -> Result<Scenario> {
        Scenario::from_spec(self.spec, self.base_dir)
    }
}

impl PheromoneSpec {
    /// A grid pheromone (eq. (2)) drawn with `colour` (screen levels per unit: r, g, b), no
    /// evaporation, diffusion, wind or maps until set.
    pub fn grid(name: impl Into<String>, colour: [f32; 3]) -> Self {
        PheromoneSpec {
            name: name.into(),
            colour,
            model: ModelKind::Grid,
            evaporation: None,
            diffusion: 0.0,
            scheme: Default::default(),
            wind: [0.0, 0.0],
            maps: Vec::new(),
            sources: Vec::new(),
            preload: false,
        }
    }

    /// A Gaussian-source pheromone (eq. (5)), sources added with [`Self::with_source`] or emitted by
    /// robots ([`RobotGroupSpec::with_emit`]).
    pub fn gaussian(name: impl Into<String>, colour: [f32; 3]) -> Self {
        PheromoneSpec {
            model: ModelKind::Gaussian,
            ..Self::grid(name, colour)
        }
    }

    /// Evaporation time e, s.
    pub fn with_evaporation(mut self, seconds: f32) -> Self {
        self.evaporation = Some(seconds);
        self
    }

    /// Diffusion coefficient d, m^2/s.
    pub fn with_diffusion(mut self, d: f32) -> Self {
        self.diffusion = d;
        self
    }

    /// Adds a static injection map.
    pub fn with_map(mut self, map: MapSpec) -> Self {
        self.maps.push(map);
        self
    }

    /// Adds a fixed Gaussian source.
    pub fn with_source(mut self, source: SourceSpec) -> Self {
        self.sources.push(source);
        self
    }
}

impl MapSpec {
    /// A trail along `points` (m), `width` m wide, injecting `rate` units per second.
    pub fn polyline(points: Vec<[f32; 2]>, width: f32, rate: f32) -> Self {
        MapSpec::Polyline {
            polyline: points,
            width,
            rate,
        }
    }
}

impl EmitSpec {
    /// A source of `k` units, `sigma` (m) wide, evaporating in `evaporation` s, on pheromone
    /// `pheromone`, that follows its robot.
    pub fn follow(pheromone: impl Into<String>, k: f32, sigma: [f32; 2], evaporation: f32) -> Self {
        EmitSpec {
            pheromone: pheromone.into(),
            k,
            sigma,
            rho: 0.0,
            evaporation,
            when: EmitWhen::Follow,
        }
    }

    /// Switched on and off by the robot's agent (one action entry; see [`EmitWhen::Action`]).
    pub fn when_action(mut self) -> Self {
        self.when = EmitWhen::Action;
        self
    }

    /// Refreshed at the robot only while it is within `distance` (m) of a robot of role `role`.
    pub fn when_near(mut self, role: impl Into<String>, distance: f32) -> Self {
        self.when = EmitWhen::Near {
            role: role.into(),
            distance,
        };
        self
    }
}

impl RobotGroupSpec {
    /// `count` robots running `behaviour` (a registry name) with its default parameters, placed at
    /// random over the arena.
    pub fn new(count: usize, behaviour: impl Into<String>) -> Self {
        RobotGroupSpec {
            count,
            role: String::new(),
            behaviour: behaviour.into(),
            params: toml::Table::new(),
            placement: Placement::Random,
            region: None,
            poses: Vec::new(),
            deposits: Vec::new(),
            deposit_actions: Vec::new(),
            emits: Vec::new(),
        }
    }

    pub fn with_role(mut self, role: impl Into<String>) -> Self {
        self.role = role.into();
        self
    }

    /// Sets one parameter of the behaviour (as `params = { key = value }` in a scenario file).
    pub fn with_param(mut self, key: impl Into<String>, value: impl Into<toml::Value>) -> Self {
        self.params.insert(key.into(), value.into());
        self
    }

    pub fn with_placement(mut self, placement: Placement) -> Self {
        self.placement = placement;
        self
    }

    /// Places the robots at `poses`, [x m, y m, heading degrees] each.
    pub fn at_poses(mut self, poses: Vec<[f32; 3]>) -> Self {
        self.placement = Placement::Explicit;
        self.poses = poses;
        self
    }

    /// The region [x0, y0, x1, y1] (m) to place the robots in.
    pub fn in_region(mut self, region: [f32; 4]) -> Self {
        self.region = Some(region);
        self
    }

    /// Adds a trail the robots lay on grid pheromone `pheromone`, `rate` units per second at the
    /// kernel's peak.
    pub fn with_deposit(mut self, pheromone: impl Into<String>, kernel: Kernel, rate: f32) -> Self {
        self.deposits.push(DepositSpec {
            pheromone: pheromone.into(),
            kernel,
            rate,
        });
        self
    }

    /// Lets the group's agents lay grid pheromone `pheromone` by action, up to `max_rate` units per
    /// second at the kernel's peak (`[[robots]] deposit_actions`).
    pub fn with_deposit_action(
        mut self,
        pheromone: impl Into<String>,
        kernel: Kernel,
        max_rate: f32,
    ) -> Self {
        self.deposit_actions.push(DepositActionSpec {
            pheromone: pheromone.into(),
            kernel,
            max_rate,
        });
        self
    }

    /// Adds a Gaussian source each robot emits.
    pub fn with_emit(mut self, emit: EmitSpec) -> Self {
        self.emits.push(emit);
        self
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The builder and a scenario file saying the same thing give the same scenario, for every
    /// builder method.
    #[test]
    fn builds_what_the_same_toml_parses_to() {
        let text = r#"
name = "every-builder-method"
screen = { resolution = [1920, 1080], size = [1.2, 0.675] }
duration = 1.5
dt = 0.01
arena = { size = [1.0, 0.6] }
seed = 11
field = { cell = 0.005 }
physics = "rapier"
output = { gif_interval = 0.5 }
pheromones = [
    { name = "trail", colour = [0, 255, 0], evaporation = 8.0, diffusion = 2e-6, maps = [{ polyline = [[0.1, 0.3], [0.9, 0.3]], width = 0.04, rate = 0.3 }] },
    { name = "alarm", colour = [255, 0, 0], model = "gaussian", evaporation = 4.0, sources = [{ k = 0.5, sigma = [0.1, 0.2], evaporation = 4.0, centre = [0.5, 0.3], start = 0.2 }] },
]
[[robots]]
count = 6
role = "scout"
behaviour = "follow"
params = { channel = "g", speed = 0.08 }
placement = "grid"
region = [0.1, 0.1, 0.5, 0.5]
deposits = [{ pheromone = "trail", kernel = { shape = "disc", radius = 0.02 }, rate = 3.0 }]
deposit_actions = [{ pheromone = "trail", kernel = { shape = "cone", radius = 0.03 }, max_rate = 6.0 }]
emits = [{ pheromone = "alarm", k = 0.4, sigma = [0.05, 0.05], evaporation = 2.0, when = { near = { role = "nest", distance = 0.1 } } }]
[[robots]]
count = 2
role = "nest"
behaviour = "avoid"
placement = "explicit"
poses = [[0.8, 0.2, 90.0], [0.8, 0.4, -90.0]]
emits = [{ pheromone = "alarm", k = 0.2, sigma = [0.03, 0.03], evaporation = 1.0, when = "action" }]
"#;
        let parsed = Scenario::from_toml_str(text, ".").unwrap();
        let alarm_source = SourceSpec {
            k: 0.5,
            sigma: [0.1, 0.2],
            rho: 0.0,
            evaporation: 4.0,
            centre: [0.5, 0.3],
            start: 0.2,
        };
        let built = ScenarioBuilder::new()
            .name("every-builder-method")
            .duration(1.5)
            .dt(0.01)
            .seed(11)
            .physics(PhysicsBackend::Rapier)
            .screen([1920, 1080], [1.2, 0.675])
            .arena([1.0, 0.6])
            .cell(0.005)
            .gif_interval(0.5)
            .pheromone(
                PheromoneSpec::grid("trail", [0.0, 255.0, 0.0])
                    .with_evaporation(8.0)
                    .with_diffusion(2e-6)
                    .with_map(MapSpec::polyline(vec![[0.1, 0.3], [0.9, 0.3]], 0.04, 0.3)),
            )
            .pheromone(
                PheromoneSpec::gaussian("alarm", [255.0, 0.0, 0.0])
                    .with_evaporation(4.0)
                    .with_source(alarm_source),
            )
            .robots(
                RobotGroupSpec::new(6, "follow")
                    .with_role("scout")
                    .with_param("channel", "g")
                    .with_param("speed", 0.08)
                    .with_placement(Placement::Grid)
                    .in_region([0.1, 0.1, 0.5, 0.5])
                    .with_deposit("trail", Kernel::Disc { radius: 0.02 }, 3.0)
                    .with_deposit_action("trail", Kernel::Cone { radius: 0.03 }, 6.0)
                    .with_emit(
                        EmitSpec::follow("alarm", 0.4, [0.05, 0.05], 2.0).when_near("nest", 0.1),
                    ),
            )
            .robots(
                RobotGroupSpec::new(2, "avoid")
                    .with_role("nest")
                    .at_poses(vec![[0.8, 0.2, 90.0], [0.8, 0.4, -90.0]])
                    .with_emit(EmitSpec::follow("alarm", 0.2, [0.03, 0.03], 1.0).when_action()),
            )
            .build()
            .unwrap();
        assert_eq!(built.to_toml(), parsed.to_toml());
        assert_eq!(built.base_dir, parsed.base_dir);
    }

    #[test]
    fn validates_as_the_toml_path_does() {
        let e = ScenarioBuilder::new()
            .pheromone(PheromoneSpec::grid("red", [255.0, 0.0, 0.0]).with_evaporation(-5.0))
            .build()
            .unwrap_err()
            .to_string();
        assert!(e.contains("pheromones[0].evaporation"), "{e}");
    }
}
