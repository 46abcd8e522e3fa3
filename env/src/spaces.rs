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
    /// The task's entries after the sensor values in the observation vector.
    pub extra_obs: Vec<crate::task::ExtraObs>,
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

/// The bounds every observation entry takes, per entry (low, high): colour intensities and bumpers
/// in `[0, 1]`, the last wheel command in `[-1, 1]` (see [`crate::encoding::encode`]).
pub fn observation_bounds() -> (Vec<f32>, Vec<f32>) {
    let dim = crate::encoding::OBS_DIM;
    let low = (0..dim)
        .map(|i| if i >= dim - 2 { -1.0 } else { 0.0 })
        .collect();
    (low, vec![1.0; dim])
}

/// The bounds every global-state entry takes, per entry, for a state of `len` entries: each
/// robot's position scaled to `[-1, 1]` and its heading's cos and sin, then the episode's elapsed
/// fraction in `[0, 1]`.
pub fn state_bounds(len: usize) -> (Vec<f32>, Vec<f32>) {
    let mut low = vec![-1.0; len];
    if let Some(last) = low.last_mut() {
        *last = 0.0;
    }
    (low, vec![1.0; len])
}

impl EnvSpec {
    /// Per-entry bounds `(low, high)` of the observation vector (tighter than the `observation`
    /// box's scalar envelope).
    pub fn observation_bounds(&self) -> (Vec<f32>, Vec<f32>) {
        let (mut low, mut high) = observation_bounds();
        low.extend(self.extra_obs.iter().map(|x| x.low));
        high.extend(self.extra_obs.iter().map(|x| x.high));
        (low, high)
    }

    /// Per-entry bounds `(low, high)` of a continuous action with deposit actions: wheels in
    /// `[-1, 1]`, deposit rates in `[0, 1]` (see [`crate::actions`]); None where the box's scalar
    /// envelope is exact (wheels only, or discrete actions).
    pub fn action_bounds(&self) -> Option<(Vec<f32>, Vec<f32>)> {
        match &self.action {
            Space::Box { shape, .. } if shape.iter().product::<usize>() > 2 => {
                let w: usize = shape.iter().product();
                let low = (0..w).map(|i| if i < 2 { -1.0 } else { 0.0 }).collect();
                Some((low, vec![1.0; w]))
            }
            _ => None,
        }
    }

    /// Per-entry bounds `(low, high)` of the global state, if it is enabled.
    pub fn state_bounds(&self) -> Option<(Vec<f32>, Vec<f32>)> {
        self.state.as_ref().map(|s| state_bounds(s.flat_len()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bounds_follow_the_encoding() {
        let (low, high) = observation_bounds();
        assert_eq!(low.len(), crate::encoding::OBS_DIM);
        assert_eq!(&low[..15], &[0.0; 15]);
        assert_eq!(&low[15..], &[-1.0, -1.0]);
        assert!(high.iter().all(|&h| h == 1.0));
        let (low, high) = state_bounds(9);
        assert_eq!(low[..8], [-1.0; 8]);
        assert_eq!((low[8], high[8]), (0.0, 1.0));
    }
}
