//! The scenario file format (TOML), as plain serde structs. Unknown keys are rejected everywhere.
//! Checking the values happens in [`super::validate`].

use crate::field::{BackendChoice, DiffusionScheme, Kernel};
use crate::robot::{ColiasParams, PhysicsBackend};
use crate::screen::ScreenSpec;
use crate::sensors::{BumperParams, ColourSensorParams};
use crate::tracker::TrackerParams;
use serde::{Deserialize, Serialize};

/// A whole scenario: arena, screen, pheromones, robots, duration, time step, seed.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ScenarioSpec {
    /// Human-readable name.
    #[serde(default)]
    pub name: String,
    /// Length of a run, s.
    pub duration: f32,
    /// Time step, s (the paper's screen refresh: 0.02).
    #[serde(default = "default_dt")]
    pub dt: f32,
    #[serde(default)]
    pub seed: u64,
    #[serde(default)]
    pub arena: ArenaSpec,
    #[serde(default)]
    pub screen: ScreenSpec,
    #[serde(default)]
    pub field: FieldSpec,
    /// Robot-robot and robot-wall contacts: `rapier` (rigid bodies, default) or `discs` (a fast
    /// position-based solver for very large swarms).
    #[serde(default)]
    pub physics: PhysicsBackend,
    #[serde(default)]
    pub robot: ColiasParams,
    #[serde(default)]
    pub sensor: ColourSensorParams,
    #[serde(default)]
    pub bumper: BumperParams,
    #[serde(default)]
    pub tracker: TrackerParams,
    #[serde(default)]
    pub output: OutputSpec,
    #[serde(default)]
    pub pheromones: Vec<PheromoneSpec>,
    #[serde(default)]
    pub robots: Vec<RobotGroupSpec>,
    /// Static obstacles (`[[obstacles]]`: boxes, discs, polygons, walls, image masks).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub obstacles: Vec<crate::arena::ObstacleSpec>,
    /// How the scenario runs on the lab's hardware (`colcos bridge`) and its twin.
    #[serde(default, skip_serializing_if = "super::rig::RigSpec::is_default")]
    pub rig: super::rig::RigSpec,
    /// Domain randomisation: ranges some parameters are drawn from when a world is built.
    #[serde(
        default,
        skip_serializing_if = "super::randomize::RandomizeSpec::is_default"
    )]
    pub randomize: super::randomize::RandomizeSpec,
    /// Robots that differ: each robot's own wheels, motor lag, command latency and sensor gain.
    #[serde(
        default,
        skip_serializing_if = "super::individual::IndividualSpec::is_default"
    )]
    pub individual: super::individual::IndividualSpec,
}

fn default_dt() -> f32 {
    0.02
}

/// The walled arena. By default it is the screen.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ArenaSpec {
    /// Width and height, m (default: the screen's size).
    pub size: Option<[f32; 2]>,
    /// A disc or polygon boundary inside that rectangle (default: the rectangle).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shape: Option<crate::arena::ArenaShape>,
}

/// Where pheromone is injected: at the tracker's poses (as in the real rig) or the true ones.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum InjectAt {
    #[default]
    Tracked,
    True,
}

/// The grid shared by all grid pheromones.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FieldSpec {
    /// Grid cell side, m.
    pub cell: f32,
    pub inject_at: InjectAt,
    /// Which backend steps the grid fields: `cpu` (default), `gpu` or `auto` (see `colcos-gpu`).
    pub backend: BackendChoice,
}

impl Default for FieldSpec {
    fn default() -> Self {
        FieldSpec {
            cell: 0.005,
            inject_at: InjectAt::Tracked,
            backend: BackendChoice::Cpu,
        }
    }
}

/// What a run writes besides the trajectory log.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct OutputSpec {
    /// Seconds between GIF frames (0: no GIF).
    pub gif_interval: f32,
    /// GIF width in pixels (height follows the screen's aspect ratio).
    pub gif_width: u32,
    /// Log every n-th tick.
    pub log_every: u32,
}

impl Default for OutputSpec {
    fn default() -> Self {
        OutputSpec {
            gif_interval: 0.2,
            gif_width: 480,
            log_every: 1,
        }
    }
}

/// Field model of one pheromone.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ModelKind {
    /// Eq. (2) on the grid.
    #[default]
    Grid,
    /// Eq. (5): Gaussian sources.
    Gaussian,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PheromoneSpec {
    pub name: String,
    /// k_j of eq. (1): screen levels (0-255 scale) per unit of pheromone, for r, g, b.
    pub colour: [f32; 3],
    #[serde(default)]
    pub model: ModelKind,
    /// Evaporation time e, s (grid: absent = no evaporation).
    pub evaporation: Option<f32>,
    /// Diffusion coefficient d, m^2/s (grid only).
    #[serde(default)]
    pub diffusion: f32,
    #[serde(default)]
    pub scheme: DiffusionScheme,
    /// Constant wind, m/s (grid only).
    #[serde(default)]
    pub wind: [f32; 2],
    /// Static injection maps (grid only).
    #[serde(default)]
    pub maps: Vec<MapSpec>,
    /// Fixed Gaussian sources (gaussian only).
    #[serde(default)]
    pub sources: Vec<SourceSpec>,
    /// Start with the field at the steady state `e J` of its static maps (grid, evaporation set, no
    /// diffusion or wind): trails already built at t = 0, as in the paper's case I.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub preload: bool,
}

/// A static injection map: a polyline with a width, or an image. Written in TOML as a table with
/// either `polyline` and `width` or `image` (and `channel`), and `rate`; which keys belong to which
/// kind is checked as the file is read (see `MapFields`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged, try_from = "MapFields")]
pub enum MapSpec {
    Polyline {
        /// Points of the polyline, m.
        polyline: Vec<[f32; 2]>,
        /// Trail width, m.
        width: f32,
        /// Injection rate J, units per second.
        rate: f32,
    },
    Image {
        /// PNG path, relative to the scenario file.
        image: String,
        /// Image channel to read: "r", "g", "b" or "luma" (default).
        #[serde(skip_serializing_if = "Option::is_none")]
        channel: Option<crate::channel::ImageChannel>,
        /// Injection rate J, units per second at full image level.
        rate: f32,
    },
}

impl MapSpec {
    /// Injection rate J, units per second (at full image level).
    pub fn rate(&self) -> f32 {
        match self {
            MapSpec::Polyline { rate, .. } | MapSpec::Image { rate, .. } => *rate,
        }
    }
}

/// A map's keys as written; [`MapSpec`] is made from them. An error names the key at fault as
/// `.key: ...`, which the parser appends to the map's own path.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct MapFields {
    polyline: Option<Vec<[f32; 2]>>,
    width: Option<f32>,
    image: Option<String>,
    channel: Option<crate::channel::ImageChannel>,
    rate: f32,
}

impl TryFrom<MapFields> for MapSpec {
    type Error = String;

    fn try_from(f: MapFields) -> Result<Self, String> {
        use crate::channel::ImageChannel;
        match (f.polyline, f.image) {
            (Some(polyline), None) => {
                if f.channel.is_some() {
                    return Err(".channel: only image maps have a channel".into());
                }
                let width = f
                    .width
                    .ok_or(".width: missing (a polyline map needs a width)")?;
                Ok(MapSpec::Polyline {
                    polyline,
                    width,
                    rate: f.rate,
                })
            }
            (None, Some(image)) => {
                if let Some(w) = f.width {
                    return Err(format!(".width: {w}: only polyline maps have a width"));
                }
                // Maps are read as RGB: their alpha is not a level.
                if f.channel == Some(ImageChannel::A) {
                    return Err(".channel: \"a\": must be \"r\", \"g\", \"b\" or \"luma\"".into());
                }
                Ok(MapSpec::Image {
                    image,
                    channel: f.channel,
                    rate: f.rate,
                })
            }
            _ => Err("give exactly one of `polyline` or `image`".into()),
        }
    }
}

/// A Gaussian source of eq. (5).
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SourceSpec {
    pub k: f32,
    /// (sigma_x, sigma_y), m.
    pub sigma: [f32; 2],
    #[serde(default)]
    pub rho: f32,
    /// Evaporation time e, s.
    pub evaporation: f32,
    /// (mu_x, mu_y), m (fixed sources only).
    #[serde(default)]
    pub centre: [f32; 2],
    /// Start time, s.
    #[serde(default)]
    pub start: f32,
}

/// How a group of robots is placed at the start.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Placement {
    /// Uniformly at random, without overlap, headings random.
    #[default]
    Random,
    /// On a regular grid over the region, headings random.
    Grid,
    /// At the poses given in `poses`.
    Explicit,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RobotGroupSpec {
    pub count: usize,
    /// A free label (`leader`, `predator`, ...): behaviours never see it; emitters can refer to it.
    #[serde(default)]
    pub role: String,
    /// Behaviour name from the registry (`wander`, `avoid`, `follow`, ...).
    pub behaviour: String,
    /// Parameters of the behaviour (checked by the behaviour's own spec).
    #[serde(default)]
    pub params: toml::Table,
    #[serde(default)]
    pub placement: Placement,
    /// Region to place robots in, [x0, y0, x1, y1], m (default: the whole arena).
    pub region: Option<[f32; 4]>,
    /// Poses [x m, y m, heading degrees] for `placement = "explicit"`.
    #[serde(default)]
    pub poses: Vec<[f32; 3]>,
    /// Trails this group lays on grid pheromones.
    #[serde(default)]
    pub deposits: Vec<DepositSpec>,
    /// Trails this group's agents choose to lay, step by step (an RL environment's pheromone
    /// actions): one action entry each, a fraction of `max_rate`.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub deposit_actions: Vec<DepositActionSpec>,
    /// Gaussian sources this group emits.
    #[serde(default)]
    pub emits: Vec<EmitSpec>,
}

impl RobotGroupSpec {
    /// The pheromones this group's agents lay by action, in the order of their action entries:
    /// `deposit_actions` (grid trails, a rate fraction each), then the `emits` switched by action
    /// (`when = "action"`, on from 0.5).
    pub fn action_pheromones(&self) -> impl Iterator<Item = &str> {
        let trails = self.deposit_actions.iter().map(|d| d.pheromone.as_str());
        let switched = (self.emits.iter())
            .filter(|e| e.when == EmitWhen::Action)
            .map(|e| e.pheromone.as_str());
        trails.chain(switched)
    }

    /// Action entries per robot of this group for laying pheromone (see [`Self::action_pheromones`]).
    pub fn action_count(&self) -> usize {
        self.action_pheromones().count()
    }

    /// A robot's behaviour as this group names it (`key`: the group's key, for errors).
    pub fn build_behaviour(
        &self,
        robot: &crate::robot::ColiasParams,
        key: &str,
    ) -> crate::error::Result<Box<dyn crate::behaviour::Behaviour>> {
        crate::behaviour::registry::build_with(&self.behaviour, &self.params, key, robot)
    }
}

/// Trail injection along each robot's path.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DepositSpec {
    pub pheromone: String,
    pub kernel: Kernel,
    /// Units per second at the kernel's peak.
    pub rate: f32,
}

/// A trail an agent lays at a rate it chooses each step: `fraction * max_rate`, along the same path
/// and with the same kernels as a [`DepositSpec`].
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DepositActionSpec {
    pub pheromone: String,
    pub kernel: Kernel,
    /// Units per second at the kernel's peak when the action is 1.
    pub max_rate: f32,
}

/// A Gaussian source attached to each robot of a group.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EmitSpec {
    pub pheromone: String,
    pub k: f32,
    pub sigma: [f32; 2],
    #[serde(default)]
    pub rho: f32,
    pub evaporation: f32,
    /// When to (re)start the source's clock at the robot's position.
    #[serde(default)]
    pub when: EmitWhen,
}

/// `follow`: the source sits at the robot and is refreshed every step (AGP follows the leader).
/// `near`: while the robot is within `distance` of a robot of role `role`, the source is moved to it and
/// its clock restarts (refreshed); away from it, the source stays and evaporates (ALP).
/// `action`: the robot's agent switches it: while its action entry is at least 0.5 the source is
/// refreshed at the robot; below, it stays and evaporates (nothing is emitted before the first "on").
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum EmitWhen {
    #[default]
    Follow,
    Near {
        role: String,
        distance: f32,
    },
    Action,
}
