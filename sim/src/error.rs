//! Errors of the simulator, as values.

use thiserror::Error;

#[derive(Debug, Error)]
pub enum SimError {
    /// A scenario file or parameter struct holds a value that cannot be simulated.
    /// `key` is the full key path (`pheromones[1].evaporation`), `value` the offending value.
    #[error("invalid scenario: `{key}` = {value}: {reason}")]
    Invalid {
        key: String,
        value: String,
        reason: String,
    },
    /// The scenario file is not valid TOML or does not match the schema (unknown key, wrong type).
    #[error("scenario file {path}: {message}")]
    Parse { path: String, message: String },
    #[error("{context}: {source}")]
    Io {
        context: String,
        #[source]
        source: std::io::Error,
    },
    #[error("image {path}: {message}")]
    Image { path: String, message: String },
}

impl SimError {
    pub fn invalid(
        key: impl Into<String>,
        value: impl std::fmt::Display,
        reason: impl Into<String>,
    ) -> Self {
        SimError::Invalid {
            key: key.into(),
            value: value.to_string(),
            reason: reason.into(),
        }
    }

    pub fn io(context: impl Into<String>, source: std::io::Error) -> Self {
        SimError::Io {
            context: context.into(),
            source,
        }
    }
}

pub type Result<T, E = SimError> = std::result::Result<T, E>;
