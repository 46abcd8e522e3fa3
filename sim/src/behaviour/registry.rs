//! Behaviours by name, as scenario files refer to them. Every behaviour reads its parameters from the
//! group's `params` table and rejects unknown keys.
use super::follow::FollowParams;
use super::paper::{FollowerParams, ForagingParams, LeaderParams};
pub use super::param_doc::ParamDoc;
use super::{Avoid, Behaviour, Follow, Wander};
use crate::error::{Result, SimError};
use crate::robot::ColiasParams;
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};

/// Builds a behaviour from what a group asks for.
type Builder = fn(&Request) -> Result<Box<dyn Behaviour>>;

/// What a behaviour is built from: the group's `params` table, its key (`robots[2]`, for errors) and
/// the robot's body (a behaviour that turns at a set yaw rate needs its wheel base).
struct Request<'a> {
    params: &'a toml::Table,
    key: &'a str,
    robot: &'a ColiasParams,
}

impl Request<'_> {
    /// The `params` table as `T` ([`parse_params`]).
    fn parse<T: DeserializeOwned>(&self) -> Result<T> {
        parse_params(self.params, self.key)
    }
}

/// A registered behaviour.
struct Entry {
    name: &'static str,
    about: &'static str,
    build: Builder,
    params: &'static [ParamDoc],
    /// The defaults of `params` as a table (what the behaviour reads when the table is empty).
    defaults: fn() -> toml::Table,
}

fn table_of<T: Default + Serialize>() -> toml::Table {
    toml::Table::try_from(T::default()).unwrap_or_default()
}

/// Every registered behaviour.
const REGISTRY: &[Entry] = &[
    Entry {
        name: "wander",
        about: "correlated random walk (bumps into things)",
        build: build_wander,
        params: WanderParams::DOCS,
        defaults: table_of::<WanderParams>,
    },
    Entry {
        name: "avoid",
        about: "random walk with a sharp turn on a bumper hit",
        build: build_avoid,
        params: WanderParams::DOCS,
        defaults: table_of::<WanderParams>,
    },
    Entry {
        name: "follow",
        about: "follow a colour trail (left/right sensor difference), wander off it, avoid on a bump",
        build: build_follow,
        params: FollowParams::DOCS,
        defaults: table_of::<FollowParams>,
    },
    Entry {
        name: "forage",
        about: "paper Algorithm 1: follow LAP/SAP trails by eq. (7), cyan 70 % at bifurcations, avoid SRP",
        build: build_forage,
        params: ForagingParams::DOCS,
        defaults: table_of::<ForagingParams>,
    },
    Entry {
        name: "aggregation_leader",
        about: "paper Algorithm 2: flee down the ALP gradient by eq. (8), else wander",
        build: build_aggregation_leader,
        params: LeaderParams::DOCS,
        defaults: table_of::<LeaderParams>,
    },
    Entry {
        name: "aggregation_follower",
        about: "paper Algorithm 3: flee the ALP, else climb the AGP gradient by eq. (8), else wander",
        build: build_aggregation_follower,
        params: FollowerParams::DOCS,
        defaults: table_of::<FollowerParams>,
    },
];

/// Names and descriptions of all behaviours.
pub fn list() -> impl Iterator<Item = (&'static str, &'static str)> {
    REGISTRY.iter().map(|e| (e.name, e.about))
}

/// The keys of behaviour `name`'s `params` table with type, default and meaning (`None`: no such
/// behaviour).
pub fn params(name: &str) -> Option<&'static [ParamDoc]> {
    REGISTRY.iter().find(|e| e.name == name).map(|e| e.params)
}

/// The default `params` table of behaviour `name`: every key it reads, at its default.
pub fn default_params(name: &str) -> Option<toml::Table> {
    REGISTRY
        .iter()
        .find(|e| e.name == name)
        .map(|e| (e.defaults)())
}

/// Builds behaviour `name` from its parameter table for a robot with the default Colias body; `key` is
/// the scenario key path used in errors.
pub fn build(name: &str, params: &toml::Table, key: &str) -> Result<Box<dyn Behaviour>> {
    build_with(name, params, key, &ColiasParams::default())
}

/// Builds behaviour `name` from its parameter table for a robot with body `robot` (`key`, e.g.
/// `robots[2]`, names it in errors): the one constructor of scenario behaviours, whoever runs them
/// (`RobotGroupSpec::build_behaviour`).
pub fn build_with(
    name: &str,
    params: &toml::Table,
    key: &str,
    robot: &ColiasParams,
) -> Result<Box<dyn Behaviour>> {
    match REGISTRY.iter().find(|e| e.name == name) {
        Some(entry) => (entry.build)(&Request { params, key, robot }),
        None => {
            let known: Vec<_> = REGISTRY.iter().map(|e| e.name).collect();
            Err(SimError::invalid(
                format!("{key}.behaviour"),
                format!("{name:?}"),
                format!("unknown behaviour (known: {known:?})"),
            ))
        }
    }
}

/// Deserialises a behaviour's `params` table, naming the key at fault and its value.
pub fn parse_params<T: DeserializeOwned>(params: &toml::Table, key: &str) -> Result<T> {
    // Every robot of every world built parses its table: the path-tracking deserializer (which
    // allocates each key it passes) runs only for a table that fails, to name the key.
    if let Ok(parsed) = T::deserialize(toml::Value::Table(params.clone())) {
        return Ok(parsed);
    }
    let value = toml::Value::Table(params.clone());
    serde_path_to_error::deserialize(value.clone()).map_err(|e| {
        let path = e.path().to_string();
        let at = if path == "." {
            format!("{key}.params")
        } else {
            format!("{key}.params.{path}")
        };
        // The value at the path as the file wrote it (the whole table for a missing or unknown key).
        let mut shown = &value;
        for seg in e.path().iter() {
            let next = match seg {
                serde_path_to_error::Segment::Map { key } => shown.get(key.as_str()),
                serde_path_to_error::Segment::Seq { index } => shown.get(*index),
                _ => None,
            };
            match next {
                Some(v) => shown = v,
                None => break,
            }
        }
        // toml's message repeats the path on a second line (`in \`speed\``): the key says it.
        let reason = e.into_inner().to_string();
        let reason = reason.lines().next().unwrap_or_default().trim().to_string();
        SimError::invalid(at, shown, reason)
    })
}

/// Parameters of `wander` and `avoid`.
#[derive(Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
struct WanderParams {
    /// Forward speed, m/s.
    speed: f32,
}

impl WanderParams {
    const DOCS: &'static [ParamDoc] = &[ParamDoc {
        name: "speed",
        ty: "float, m/s, >= 0",
        default: "0.1",
        meaning: "mean wheel speed of the random walk",
    }];
}

impl Default for WanderParams {
    fn default() -> Self {
        WanderParams { speed: 0.1 }
    }
}

fn speed_checked(key: &str, speed: f32) -> Result<f32> {
    if speed.is_finite() && speed >= 0.0 {
        Ok(speed)
    } else {
        Err(SimError::invalid(
            format!("{key}.params.speed"),
            speed,
            "must be a finite speed >= 0 (m/s)",
        ))
    }
}

fn build_wander(r: &Request) -> Result<Box<dyn Behaviour>> {
    let p: WanderParams = r.parse()?;
    Ok(Box::new(Wander::new(speed_checked(r.key, p.speed)?)))
}

fn build_avoid(r: &Request) -> Result<Box<dyn Behaviour>> {
    let p: WanderParams = r.parse()?;
    Ok(Box::new(Avoid::new(Wander::new(speed_checked(
        r.key, p.speed,
    )?))))
}

fn build_follow(r: &Request) -> Result<Box<dyn Behaviour>> {
    let key = r.key;
    let p: FollowParams = r.parse()?;
    let channel = p.channel.index();
    let speed = speed_checked(key, p.speed)?;
    if !p.sensitivity.is_finite() {
        return Err(SimError::invalid(
            format!("{key}.params.sensitivity"),
            p.sensitivity,
            "must be finite",
        ));
    }
    if !(p.threshold.is_finite() && p.threshold >= 0.0) {
        return Err(SimError::invalid(
            format!("{key}.params.threshold"),
            p.threshold,
            "must be >= 0",
        ));
    }
    Ok(Box::new(Avoid::new(Follow::new(
        channel,
        speed,
        p.sensitivity,
        p.threshold,
    ))))
}

fn build_forage(r: &Request) -> Result<Box<dyn Behaviour>> {
    let p: ForagingParams = r.parse()?;
    p.validate(r.key)?;
    let mut forage = super::paper::Foraging::new(p);
    forage.wheel_base = r.robot.wheel_base;
    Ok(Box::new(forage))
}

fn build_aggregation_leader(r: &Request) -> Result<Box<dyn Behaviour>> {
    let p: LeaderParams = r.parse()?;
    Ok(Box::new(super::paper::Leader::new(p.validate(r.key)?)))
}

fn build_aggregation_follower(r: &Request) -> Result<Box<dyn Behaviour>> {
    let p: FollowerParams = r.parse()?;
    Ok(Box::new(super::paper::Follower::new(p.validate(r.key)?)))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn documented_defaults(docs: &[ParamDoc]) -> toml::Table {
        docs.iter()
            .map(|d| {
                let v: toml::Table = toml::from_str(&format!("v = {}", d.default))
                    .unwrap_or_else(|e| panic!("default of `{}` is not TOML: {e}", d.name));
                (d.name.to_string(), v["v"].clone())
            })
            .collect()
    }

    /// Every key a behaviour reads is documented, with its true default, and nothing else is.
    #[test]
    fn params_are_documented_with_their_defaults() {
        for entry in REGISTRY {
            let name = entry.name;
            let documented = documented_defaults(entry.params);
            let actual = (entry.defaults)();
            assert!(!actual.is_empty(), "{name}: no parameters serialised");
            let doc_keys: Vec<_> = documented.keys().collect();
            let keys: Vec<_> = actual.keys().collect();
            assert_eq!(
                doc_keys, keys,
                "{name}: documented keys vs the params struct"
            );
            for (k, v) in &actual {
                let doc = &documented[k];
                let same = match (
                    v.as_float(),
                    doc.as_float().or(doc.as_integer().map(|i| i as f64)),
                ) {
                    (Some(a), Some(b)) => (a - b).abs() <= 1e-6 * a.abs().max(1.0),
                    _ => v == doc,
                };
                assert!(same, "{name}.{k}: default {v} but documented as {doc}");
            }
            build(name, &documented, "robots[0]")
                .unwrap_or_else(|e| panic!("{name} with every documented key: {e}"));
            let mut extra = documented.clone();
            extra.insert("not_a_parameter".into(), toml::Value::Float(1.0));
            assert!(
                build(name, &extra, "robots[0]").is_err(),
                "{name} accepts an undocumented key"
            );
            for d in entry.params {
                assert!(
                    !d.ty.is_empty() && !d.meaning.is_empty(),
                    "{name}.{}",
                    d.name
                );
            }
        }
    }
}
