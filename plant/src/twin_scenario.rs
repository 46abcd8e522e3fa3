//! The scenario the in-process twin plays when it differs from the host's: the twin holds the "true"
//! values (tracker latency, sensor gain and crosstalk, robot body) that the host only assumes, as a
//! real rig would. Only values that leave the two sides talking about the same arena may differ.
use crate::PlantError;
use colcos_sim::scenario::Scenario;

/// What the twin plays instead of the host's scenario.
#[derive(Clone, Debug)]
pub enum TwinScenario {
    /// A whole scenario of its own (same robots, arena, screen and tick).
    Full(Box<Scenario>),
    /// The host's scenario with these dotted key paths (`"tracker.latency"`, `"sensor.gain"`) set.
    Overrides(Vec<(String, serde_json::Value)>),
}

impl TwinScenario {
    /// The twin's scenario for the host's `host` (seeded as the host).
    pub fn resolve(&self, host: &Scenario) -> Result<Scenario, PlantError> {
        let mut twin = match self {
            TwinScenario::Full(s) => (**s).clone(),
            TwinScenario::Overrides(sets) => with_overrides(host, sets)?,
        };
        twin.spec.seed = host.spec.seed;
        check_same_arena(host, &twin)?;
        Ok(twin)
    }
}

/// `host` with every `(key path, value)` of `sets` replaced, checked again as a scenario.
fn with_overrides(
    host: &Scenario,
    sets: &[(String, serde_json::Value)],
) -> Result<Scenario, PlantError> {
    let mut tree = serde_json::to_value(&host.spec)
        .map_err(|e| PlantError::option("twin_scenario", e.to_string()))?;
    for (path, value) in sets {
        let key = format!("twin_scenario.{path}");
        let mut node = &mut tree;
        let parts: Vec<&str> = path.split('.').collect();
        for (k, part) in parts.iter().enumerate() {
            let last = k + 1 == parts.len();
            let Some(table) = node.as_object_mut() else {
                return Err(PlantError::option(&key, "is not a key of a table"));
            };
            // Optional fields left out of the host's scenario may be set; no other new key may.
            let allowed = table.contains_key(*part)
                || (last && host_allows_new(parts[..k].join(".").as_str()));
            if !allowed {
                return Err(PlantError::option(
                    &key,
                    format!("the scenario has no `{part}` there"),
                ));
            }
            if last {
                table.insert((*part).to_string(), value.clone());
                break;
            }
            node = table.get_mut(*part).expect("checked above");
        }
    }
    let spec = serde_json::from_value(tree)
        .map_err(|e| PlantError::option("twin_scenario", e.to_string()))?;
    Scenario::from_spec(spec, host.base_dir.clone())
        .map_err(|e| PlantError::option("twin_scenario", e.to_string()))
}

/// Tables whose optional entries are left out of a serialised scenario when unset.
fn host_allows_new(table: &str) -> bool {
    matches!(table, "rig" | "arena")
}

/// Refuses a twin that would not be the host's arena: other robots, arena, screen, tick or radio
/// addresses would make the host track and command robots that do not exist.
fn check_same_arena(host: &Scenario, twin: &Scenario) -> Result<(), PlantError> {
    let differ = |key: &str, h: String, t: String| {
        PlantError::option(
            &format!("twin_scenario.{key}"),
            format!("{t} on the twin but {h} on the host: the twin must play the host's arena"),
        )
    };
    let (h, t) = (&host.spec, &twin.spec);
    if host.robot_count() != twin.robot_count() {
        return Err(differ(
            "robots",
            format!("{} robots", host.robot_count()),
            format!("{} robots", twin.robot_count()),
        ));
    }
    if host.arena_size() != twin.arena_size() {
        let (a, b) = (host.arena_size(), twin.arena_size());
        return Err(differ("arena.size", format!("{a:?}"), format!("{b:?}")));
    }
    if h.screen.size != t.screen.size {
        return Err(differ(
            "screen.size",
            format!("{:?}", h.screen.size),
            format!("{:?}", t.screen.size),
        ));
    }
    if h.dt != t.dt {
        return Err(differ("dt", h.dt.to_string(), t.dt.to_string()));
    }
    let n = host.robot_count();
    let ids = |s: &Scenario| {
        (
            (0..n).map(|i| s.spec.rig.tracker_id(i)).collect::<Vec<_>>(),
            s.spec.rig.radio_addresses(n).ok(),
        )
    };
    let ((ht, hr), (tt, tr)) = (ids(host), ids(twin));
    if ht != tt {
        return Err(differ(
            "rig.tracker_ids",
            format!("{ht:?}"),
            format!("{tt:?}"),
        ));
    }
    if hr != tr {
        return Err(differ(
            "rig.radio_ids",
            format!("{hr:?}"),
            format!("{tr:?}"),
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use colcos_env::task::registry;
    use serde_json::json;

    fn host() -> Scenario {
        registry::build("aggregation", &Default::default(), &json!({}))
            .unwrap()
            .1
    }

    fn over(sets: &[(&str, serde_json::Value)]) -> Result<Scenario, PlantError> {
        let sets = sets
            .iter()
            .map(|(k, v)| (k.to_string(), v.clone()))
            .collect();
        TwinScenario::Overrides(sets).resolve(&host())
    }

    #[test]
    fn overrides_change_only_what_they_name() {
        let twin = over(&[
            ("tracker.latency", json!(0.15)),
            ("sensor.gain", json!(0.7)),
        ])
        .unwrap();
        let h = host();
        assert_eq!(twin.spec.tracker.latency, 0.15);
        assert_eq!(twin.spec.sensor.gain, 0.7);
        assert_eq!(twin.spec.robot.radius, h.spec.robot.radius);
        assert_ne!(h.spec.tracker.latency, 0.15);
    }

    #[test]
    fn a_twin_of_another_arena_or_an_unknown_key_is_refused_by_name() {
        let err = |sets: &[(&str, serde_json::Value)]| over(sets).unwrap_err().to_string();
        let n = host().robot_count();
        let groups = serde_json::to_value(&host().spec.robots).unwrap();
        let mut more = groups.clone();
        more[0]["count"] = json!(n + 1);
        assert!(err(&[("robots", more)]).contains("`twin_scenario.robots`"));
        // A smaller screen is a smaller arena (the arena defaults to the screen).
        let e = err(&[("screen.size", json!([0.5, 0.5]))]);
        assert!(e.contains("`twin_scenario.arena.size`"), "{e}");
        assert!(err(&[("dt", json!(0.04))]).contains("`twin_scenario.dt`"));
        assert!(err(&[("tracker.latncy", json!(0.1))]).contains("`twin_scenario.tracker.latncy`"));
        assert!(err(&[("tracker.latency.x", json!(0.1))]).contains("tracker.latency.x"));
        // A value the scenario refuses is named by the scenario's own check.
        assert!(err(&[("tracker.latency", json!(-1.0))]).contains("latency"));
    }
}
