//! What can go wrong in a sweep, each error naming where: the key path and value of a bad sweep file,
//! the combination whose scenario fails validation, the file that could not be written.
use colcos_sim::error::SimError;

/// A sweep's error.
#[derive(Debug, thiserror::Error)]
pub enum SweepError {
    /// The sweep file is not valid TOML or does not fit the format (unknown key, wrong type).
    #[error("invalid sweep file {file}: {message}")]
    Parse { file: String, message: String },
    /// A key of the sweep file has a bad value.
    #[error("invalid sweep: `{key}` = {value}: {reason}")]
    Invalid {
        key: String,
        value: String,
        reason: String,
    },
    /// A key of the sweep file has a bad value; `file` names the sweep file.
    #[error("invalid sweep {file}: `{key}` = {value}: {reason}")]
    InvalidIn {
        file: String,
        key: String,
        value: String,
        reason: String,
    },
    /// An axis sets a scenario key to a value the scenario refuses (or a key it does not have).
    #[error("invalid sweep {file}: {setting} (combination {combo}): {reason}")]
    Axis {
        file: String,
        /// `axes[i] (name) sets key = value`: the axis (its name when it has its own), key and value.
        setting: String,
        combo: usize,
        reason: String,
    },
    /// The scenario of one combination fails the scenario checks, for no single axis.
    #[error("invalid sweep {file}: combination {combo} ({params}), seed {seed}: {source}")]
    Combination {
        file: String,
        combo: usize,
        params: String,
        seed: u64,
        #[source]
        source: Box<SimError>,
    },
    /// The base scenario cannot be read or parsed.
    #[error("base scenario {path}: {source}")]
    Base {
        path: String,
        #[source]
        source: SimError,
    },
    /// A run id that the plan does not have.
    #[error("run {id} does not exist: the sweep has runs 0..{total}")]
    NoSuchRun { id: u64, total: u64 },
    /// An output directory already holds the table of another sweep.
    #[error(
        "{dir} holds the results of a different sweep (its table's header or fingerprint differs): \
         choose another output directory or delete {dir}/results.csv to start again"
    )]
    OtherSweep { dir: String },
    /// Another process is writing the same table.
    #[error(
        "another sweep is writing {path}: wait for it to end, or choose another output directory"
    )]
    Busy { path: String },
    /// `resume` was asked for but there is nothing to resume.
    #[error("nothing to resume: {path} does not exist")]
    NothingToResume { path: String },
    #[error("{context}: {source}")]
    Io {
        context: String,
        #[source]
        source: std::io::Error,
    },
    #[error("{context}: {source}")]
    Csv {
        context: String,
        #[source]
        source: csv::Error,
    },
    /// A run failed after its scenario passed validation.
    #[error("run {id}: {message}")]
    Run { id: u64, message: String },
}

impl SweepError {
    pub(crate) fn invalid(
        key: impl Into<String>,
        value: impl std::fmt::Display,
        reason: impl Into<String>,
    ) -> Self {
        SweepError::Invalid {
            key: key.into(),
            value: shorten(value.to_string()),
            reason: reason.into(),
        }
    }

    /// The same error naming the sweep file it is about.
    pub(crate) fn in_file(self, file: &str) -> Self {
        match self {
            SweepError::Invalid { key, value, reason } => SweepError::InvalidIn {
                file: file.to_string(),
                key,
                value,
                reason,
            },
            other => other,
        }
    }

    /// `axes[i] (name) sets key = value`, the name only where it is not the key.
    pub(crate) fn setting(index: usize, name: &str, key: &str, value: &toml::Value) -> String {
        let first = if name == key {
            format!("axes[{index}]")
        } else {
            format!("axes[{index}] ({name})")
        };
        format!("{first} sets {key} = {}", shorten(value.to_string()))
    }

    pub(crate) fn io(context: impl Into<String>, source: std::io::Error) -> Self {
        SweepError::Io {
            context: context.into(),
            source,
        }
    }

    pub(crate) fn csv(context: impl Into<String>, source: csv::Error) -> Self {
        SweepError::Csv {
            context: context.into(),
            source,
        }
    }
}

/// A value cut to 80 characters: an error line stays one readable line.
fn shorten(value: String) -> String {
    if value.chars().count() > 80 {
        format!("{}...", value.chars().take(77).collect::<String>())
    } else {
        value
    }
}

pub type Result<T, E = SweepError> = std::result::Result<T, E>;
