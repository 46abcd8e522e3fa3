//! How a behaviour documents the keys of its `params` table (read by `colcos behaviours` and
//! `colcos.behaviour_params()`): beside each behaviour, below the registry that lists them.

/// One key of a behaviour's `params` table, for `colcos behaviours` and `colcos.behaviour_params()`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ParamDoc {
    pub name: &'static str,
    /// TOML type, unit and allowed range.
    pub ty: &'static str,
    /// The value used when the key is left out, as TOML.
    pub default: &'static str,
    pub meaning: &'static str,
}
