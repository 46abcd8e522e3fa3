//! colcos-env: reinforcement-learning tasks over `colcos-sim` worlds, and a batched vector environment.
//!
//! A [`Task`] turns a scenario into an RL problem: which robots are agents, how an agent's own sensor
//! reading becomes its observation vector ([`encoding`]), how its action becomes a wheel command, its
//! reward and its termination. Tasks live one per file under [`task`] and are built by name through
//! [`task::registry`]. [`VecEnv`] steps `E` worlds of `N` agents each with rayon into flat buffers
//! allocated once (`[E, N, ...]`, row-major), with per-world random streams derived from
//! `(seed, world index, episode)`, so results never depend on the number of threads.
//!
//! Robots that are not agents (a leader, a predator) keep the behaviour their scenario gives them, with
//! their own random streams: one controller per robot, inside the world's step
//! (`World::step_with_overrides`). [`episode`] and [`actions`] are the episode core every environment
//! of a task shares, the batch's worlds and the plants' arena alike.

pub mod actions;
pub mod backend;
pub mod baseline;
mod batch_step;
pub mod config;
pub mod encoding;
pub mod episode;
pub mod error;
#[cfg(feature = "gpu")]
mod gpu_stage;
#[cfg(feature = "gpu")]
mod gpu_step;
pub mod outputs;
pub mod patch;
pub mod policy;
pub mod spaces;
pub mod task;
mod vec_env;
pub mod world_output;
mod world_slot;
mod world_step;

pub use actions::{ActionDecoder, Actions};
pub use backend::EnvBackend;
pub use config::{ActionKind, AutoresetMode, EnvConfig, PatchConfig, ScenarioSource};
pub use episode::{AgentOut, Episode, StepEnd};
pub use error::{EnvError, Result};
pub use outputs::{BufferPtrs, OutSlices, Outputs, Writer};
pub use spaces::{EnvSpec, Space};
pub use task::Task;
pub use vec_env::{GPU_STAGE_PARTS, VecEnv, shield_bits};
pub use world_slot::world_index;
