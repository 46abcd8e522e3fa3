//! A combination whose scenario fails, told in the sweep's own terms: the sweep file, the axis, the key
//! it sets and the value, on one line. The scenario a combination runs is generated (the base with the
//! axis values set), so the parser's line numbers, source lines and Rust type names would point the
//! user into a file they never see.
use crate::axis::Axis;
use crate::error::SweepError;
use colcos_sim::error::SimError;
use colcos_sim::scenario::ScenarioSpec;

/// What an error needs to know of the plan: the sweep file, the axes, and the combination.
pub(crate) struct Combination<'a> {
    pub file: &'a str,
    pub axes: &'a [Axis],
    /// Its index, one value per axis, and those values as `Plan::describe` says them.
    pub index: usize,
    pub values: &'a [toml::Value],
    pub described: String,
    pub seed: u64,
}

/// The error of a combination whose scenario `table` failed with `err`.
pub(crate) fn combination_error(c: &Combination, table: &toml::Table, err: SimError) -> SweepError {
    let found = match &err {
        SimError::Parse { .. } => parse_failure(table),
        SimError::Invalid { key, reason, .. } => Some((key.clone(), reason.clone())),
        _ => None,
    };
    let Some((path, reason)) = found else {
        return whole_combination(c, err);
    };
    match find_axis(c.axes, &path) {
        Some(i) => {
            let axis = &c.axes[i];
            // The key the error is about, among the axis's keys.
            let key = axis
                .keys
                .iter()
                .map(|k| k.to_string())
                .find(|k| inside(&path, k) || inside(k, &path))
                .unwrap_or_else(|| axis.keys[0].to_string());
            SweepError::Axis {
                file: c.file.to_string(),
                setting: SweepError::setting(i, &axis.name, &key, &c.values[i]),
                combo: c.index,
                reason,
            }
        }
        None => {
            let source = match err {
                // The generated text's line numbers mean nothing to the user: the key path and reason.
                SimError::Parse { .. } => SimError::Parse {
                    path: "(the base scenario with this combination's values)".into(),
                    message: format!("at `{path}`: {reason}"),
                },
                other => other,
            };
            whole_combination(c, source)
        }
    }
}

fn whole_combination(c: &Combination, source: SimError) -> SweepError {
    SweepError::Combination {
        file: c.file.to_string(),
        combo: c.index,
        params: c.described.clone(),
        seed: c.seed,
        source: Box::new(source),
    }
}

/// The key path and a plain reason of a scenario table the scenario format refuses, read again from
/// the table itself (no text, so no line numbers).
fn parse_failure(table: &toml::Table) -> Option<(String, String)> {
    let e = serde_path_to_error::deserialize::<_, ScenarioSpec>(toml::Value::Table(table.clone()))
        .err()?;
    let path = e.path().to_string();
    let inner = e.into_inner().to_string();
    // The first line: the value deserializer adds `in <table>` lines the path already says.
    let inner = inner.lines().next().unwrap_or_default().trim().to_string();
    Some((path.clone(), plain_reason(&path, &inner)))
}

/// `a` is `b` or a key inside it.
fn inside(a: &str, b: &str) -> bool {
    a == b
        || a.strip_prefix(b)
            .is_some_and(|rest| rest.starts_with('.') || rest.starts_with('['))
}

/// The axis an error at `path` is about: one that sets `path` or a table holding it, else the only
/// axis that sets a key inside `path` (several: the combination as a whole is named instead).
fn find_axis(axes: &[Axis], path: &str) -> Option<usize> {
    let keys = |i: usize| axes[i].keys.iter().map(|k| k.to_string());
    let n = axes.len();
    if let Some(i) = (0..n).find(|&i| keys(i).any(|k| inside(path, &k))) {
        return Some(i);
    }
    let below: Vec<usize> = (0..n)
        .filter(|&i| keys(i).any(|k| inside(&k, path)))
        .collect();
    (below.len() == 1).then(|| below[0])
}

/// Serde's message in the scenario's words: unknown keys with the keys their table takes, and types
/// by what a TOML file writes (a table, an integer) rather than Rust's names.
fn plain_reason(path: &str, inner: &str) -> String {
    if let Some(rest) = inner.strip_prefix("unknown field `") {
        let takes = rest
            .split_once(", expected ")
            .map(|(_, e)| e.trim_start_matches("one of "))
            .unwrap_or("no keys");
        let parent = match path.rfind(['.', '[']) {
            Some(k) => format!("`{}`", &path[..k]),
            None => "the top level".to_string(),
        };
        return format!("the scenario has no key `{path}`: {parent} takes {takes}");
    }
    if let Some(rest) = inner.strip_prefix("unknown variant `") {
        let (name, expected) = rest.split_once("`, expected ").unwrap_or((rest, "?"));
        return format!(
            "`{name}` is not one of {}",
            expected.trim_start_matches("one of ")
        );
    }
    plain_types(inner)
}

fn plain_types(s: &str) -> String {
    let words: Vec<&str> = s.split(' ').collect();
    let mut out: Vec<String> = Vec::with_capacity(words.len());
    let mut k = 0;
    while k < words.len() {
        let w = words[k];
        let core = w.trim_end_matches([',', '.', ';']);
        let tail = &w[core.len()..];
        let plain = match core {
            "struct" | "enum" if k + 1 < words.len() => {
                // `struct RobotGroupSpec,` -> `a table,` (the name's punctuation kept).
                let next = words[k + 1];
                let next_tail = &next[next.trim_end_matches([',', '.', ';']).len()..];
                out.push(format!(
                    "{}{next_tail}",
                    if core == "struct" {
                        "a table"
                    } else {
                        "a name"
                    }
                ));
                k += 2;
                continue;
            }
            "usize" | "u8" | "u16" | "u32" | "u64" => Some("an integer >= 0"),
            "isize" | "i8" | "i16" | "i32" | "i64" => Some("an integer"),
            "f32" | "f64" => Some("a number"),
            "bool" => Some("true or false"),
            "sequence" => Some("array"),
            "map" => Some("table"),
            _ => None,
        };
        out.push(match plain {
            Some(p) => format!("{p}{tail}"),
            None => w.to_string(),
        });
        k += 1;
    }
    out.join(" ").replace("a array", "an array")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn serde_words_become_toml_words() {
        assert_eq!(
            plain_reason(
                "tracker.latencyy",
                "unknown field `latencyy`, expected one of `rate_hz`, `latency`"
            ),
            "the scenario has no key `tracker.latencyy`: `tracker` takes `rate_hz`, `latency`"
        );
        assert_eq!(
            plain_reason(
                "robots[1]",
                "invalid type: integer `3`, expected struct RobotGroupSpec"
            ),
            "invalid type: integer `3`, expected a table"
        );
        assert_eq!(
            plain_reason(
                "robots[1].count",
                "invalid value: integer `-3`, expected usize"
            ),
            "invalid value: integer `-3`, expected an integer >= 0"
        );
        assert_eq!(
            plain_reason("x", "invalid type: string \"a\", expected a sequence"),
            "invalid type: string \"a\", expected an array"
        );
        assert!(inside("robots[1].count", "robots[1]") && !inside("robots[10]", "robots[1]"));
    }
}
