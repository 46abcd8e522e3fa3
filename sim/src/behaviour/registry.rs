//! Behaviours by name, as scenario files refer to them. Every behaviour reads its parameters from the
//! group's `params` table and rejects unknown keys.
use super::follow::{FollowParams, channel_index};
use super::{Avoid, Behaviour, Follow, Wander};
use crate::error::{Result, SimError};
use crate::robot::ColiasParams;
use crate::scenario::RobotGroupSpec;
use serde::Deserialize;
use serde::de::DeserializeOwned;

/// Builds a behaviour from its `params` table (`key` names it in errors) for a robot with `robot`'s
/// body (a behaviour that turns at a set yaw rate needs its wheel base).
type Builder = fn(&toml::Table, &str, &ColiasParams) -> Result<Box<dyn Behaviour>>;

/// Every registered behaviour: name, one-line description, builder.
const REGISTRY: &[(&str, &str, Builder)] = &[
    (
        "wander",
        "correlated random walk (bumps into things)",
        build_wander,
    ),
    (
        "avoid",
        "random walk with a sharp turn on a bumper hit",
        build_avoid,
    ),
    (
        "follow",
        "follow a colour trail (left/right sensor difference), wander off it, avoid on a bump",
        build_follow,
    ),
    (
        "forage",
        "paper Algorithm 1: follow LAP/SAP trails by eq. (7), cyan 70 % at bifurcations, avoid SRP",
        build_forage,
    ),
    (
        "aggregation_leader",
        "paper Algorithm 2: flee down the ALP gradient by eq. (8), else wander",
        build_aggregation_leader,
    ),
    (
        "aggregation_follower",
        "paper Algorithm 3: flee the ALP, else climb the AGP gradient by eq. (8), else wander",
        build_aggregation_follower,
    ),
];

/// Names and descriptions of all behaviours.
pub fn list() -> impl Iterator<Item = (&'static str, &'static str)> {
    REGISTRY.iter().map(|(n, d, _)| (*n, *d))
}

/// Builds behaviour `name` from its parameter table for a robot with the default Colias body; `key` is
/// the scenario key path used in errors.
pub fn build(name: &str, params: &toml::Table, key: &str) -> Result<Box<dyn Behaviour>> {
    build_with(name, params, key, &ColiasParams::default())
}

/// The behaviour of every robot of `group` (`key`, e.g. `robots[2]`, names it in errors), for a robot
/// with the scenario's body `robot`: the one constructor of scenario behaviours, whoever runs them.
pub fn build_for_group(
    group: &RobotGroupSpec,
    robot: &ColiasParams,
    key: &str,
) -> Result<Box<dyn Behaviour>> {
    build_with(&group.behaviour, &group.params, key, robot)
}

/// Builds behaviour `name` from its parameter table for a robot with body `robot`.
pub fn build_with(
    name: &str,
    params: &toml::Table,
    key: &str,
    robot: &ColiasParams,
) -> Result<Box<dyn Behaviour>> {
    match REGISTRY.iter().find(|(n, _, _)| *n == name) {
        Some((_, _, builder)) => builder(params, key, robot),
        None => {
            let known: Vec<_> = REGISTRY.iter().map(|(n, _, _)| *n).collect();
            Err(SimError::invalid(
                format!("{key}.behaviour"),
                format!("{name:?}"),
                format!("unknown behaviour (known: {known:?})"),
            ))
        }
    }
}

/// Deserialises a behaviour's `params` table, naming the key at fault.
pub fn parse_params<T: DeserializeOwned>(params: &toml::Table, key: &str) -> Result<T> {
    let value = toml::Value::Table(params.clone());
    serde_path_to_error::deserialize(value).map_err(|e| {
        let path = e.path().to_string();
        let at = if path == "." {
            format!("{key}.params")
        } else {
            format!("{key}.params.{path}")
        };
        SimError::invalid(at, "(see message)", e.into_inner().to_string())
    })
}

#[derive(Deserialize)]
#[serde(default, deny_unknown_fields)]
struct WanderParams {
    /// Forward speed, m/s.
    speed: f32,
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

fn build_wander(params: &toml::Table, key: &str, _: &ColiasParams) -> Result<Box<dyn Behaviour>> {
    let p: WanderParams = parse_params(params, key)?;
    Ok(Box::new(Wander::new(speed_checked(key, p.speed)?)))
}

fn build_avoid(params: &toml::Table, key: &str, _: &ColiasParams) -> Result<Box<dyn Behaviour>> {
    let p: WanderParams = parse_params(params, key)?;
    Ok(Box::new(Avoid::new(Wander::new(speed_checked(
        key, p.speed,
    )?))))
}

fn build_follow(params: &toml::Table, key: &str, _: &ColiasParams) -> Result<Box<dyn Behaviour>> {
    let p: FollowParams = parse_params(params, key)?;
    let channel = channel_index(&p.channel).ok_or_else(|| {
        SimError::invalid(
            format!("{key}.params.channel"),
            format!("{:?}", p.channel),
            "must be \"r\", \"g\" or \"b\"",
        )
    })?;
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

fn build_forage(
    params: &toml::Table,
    key: &str,
    robot: &ColiasParams,
) -> Result<Box<dyn Behaviour>> {
    let p: super::paper::ForagingParams = parse_params(params, key)?;
    p.validate(key)?;
    let mut forage = super::paper::Foraging::new(p);
    forage.wheel_base = robot.wheel_base;
    Ok(Box::new(forage))
}

fn build_aggregation_leader(
    params: &toml::Table,
    key: &str,
    _: &ColiasParams,
) -> Result<Box<dyn Behaviour>> {
    let p: super::paper::LeaderParams = parse_params(params, key)?;
    Ok(Box::new(super::paper::Leader::new(p.validate(key)?)))
}

fn build_aggregation_follower(
    params: &toml::Table,
    key: &str,
    _: &ColiasParams,
) -> Result<Box<dyn Behaviour>> {
    let p: super::paper::FollowerParams = parse_params(params, key)?;
    Ok(Box::new(super::paper::Follower::new(p.validate(key)?)))
}
