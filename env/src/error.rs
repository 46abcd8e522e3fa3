//! Errors of the environment layer, as values. Every message names what was wrong.
use colcos_sim::error::SimError;
use thiserror::Error;

#[derive(Debug, Error)]
pub enum EnvError {
    /// The scenario could not be read, parsed, validated or built.
    #[error(transparent)]
    Scenario(#[from] SimError),
    /// No task of that name is registered.
    #[error("unknown task {name:?} (known tasks: {known})")]
    UnknownTask { name: String, known: String },
    /// A task or environment parameter is unknown or out of range; `key` names it.
    #[error("invalid parameter `{key}`: {reason}")]
    Param { key: String, reason: String },
    /// Actions of the wrong shape, non-finite, or out of the action space.
    #[error("invalid actions: {0}")]
    Action(String),
    /// A call that is not valid in the environment's current state (e.g. step before reset).
    #[error("{0}")]
    State(String),
    /// The field backend asked for cannot be used (e.g. `gpu` where there is no GPU adapter).
    #[error("{0}")]
    Backend(String),
}

impl EnvError {
    pub fn param(key: impl Into<String>, reason: impl Into<String>) -> Self {
        EnvError::Param {
            key: key.into(),
            reason: reason.into(),
        }
    }
}

pub type Result<T, E = EnvError> = std::result::Result<T, E>;
