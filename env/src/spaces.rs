//! Spaces of an environment, described once in Rust; the Python PettingZoo and Gymnasium faces are
//! generated from this one spec.

/// One space, as Gymnasium names them.
#[derive(Clone, Debug, PartialEq)]
pub enum Space {
    /// `Box(low, high, shape, dtype)`; `dtype` is `"float32"` or `"uint8"`.
    Box {
        low: f32,
        high: f32,
        shape: Vec<usize>,
        dtype: &'static str,
    },
    /// `Discrete(n)`.
    Discrete { n: usize },
}

impl Space {
    /// Number of scalars in one sample.
    pub fn flat_len(&self) -> usize {
        match self {
            Space::Box { shape, .. } => shape.iter().product(),
            Space::Discrete { .. } => 1,
        }
    }
}

/// Everything a binding needs to expose the environment: sizes, spaces and names.
#[derive(Clone, Debug)]
pub struct EnvSpec {
    /// Task name, e.g. `"aggregation"`.
    pub task: String,
    /// Versioned environment name, e.g. `"colcos_aggregation_v0"`.
    pub env_name: String,
    pub num_envs: usize,
    /// Agents per world.
    pub num_agents: usize,
    /// Robots per world (agents and scripted robots).
    pub num_robots: usize,
    /// Agent names, `robot_0..`.
    pub agent_names: Vec<String>,
    /// World robot index of each agent.
    pub agent_robots: Vec<usize>,
    /// Per-agent observation vector.
    pub observation: Space,
    pub action: Space,
    /// Global state for centralised critics (if enabled).
    pub state: Option<Space>,
    /// Egocentric screen patch (if enabled): `[P, P, 3]` uint8.
    pub patch: Option<Space>,
    /// Steps per episode before truncation.
    pub max_cycles: u64,
    /// Simulation time step, s.
    pub dt: f32,
}
