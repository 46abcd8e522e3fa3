//! Scenario key paths (`pheromones[0].evaporation`, `robots[1].params.speed`) and setting one in a
//! scenario's TOML before it is parsed, so that every scenario check applies to the swept value.
use std::fmt;

/// One step of a key path.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Segment {
    Key(String),
    Index(usize),
}

/// A parsed key path.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct KeyPath {
    pub segments: Vec<Segment>,
}

impl fmt::Display for KeyPath {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (n, s) in self.segments.iter().enumerate() {
            match s {
                Segment::Key(k) if n == 0 => write!(f, "{k}")?,
                Segment::Key(k) => write!(f, ".{k}")?,
                Segment::Index(i) => write!(f, "[{i}]")?,
            }
        }
        Ok(())
    }
}

impl KeyPath {
    /// Parses `a.b[2].c`; the error says what is wrong with it.
    pub fn parse(text: &str) -> Result<Self, String> {
        let mut segments = Vec::new();
        let mut rest = text.trim();
        if rest.is_empty() {
            return Err("an empty key path".into());
        }
        let mut expect_key = true;
        while !rest.is_empty() {
            if let Some(r) = rest.strip_prefix('[') {
                let end = r.find(']').ok_or("a `[` without its `]`")?;
                let index = r[..end]
                    .trim()
                    .parse::<usize>()
                    .map_err(|_| format!("`[{}]` is not an array index", &r[..end]))?;
                if segments.is_empty() {
                    return Err("a key path starts with a key, not an index".into());
                }
                segments.push(Segment::Index(index));
                rest = &r[end + 1..];
                expect_key = false;
            } else {
                if !expect_key {
                    rest = rest
                        .strip_prefix('.')
                        .ok_or_else(|| format!("expected `.` or `[` before `{rest}`"))?;
                }
                let end = rest.find(['.', '[']).unwrap_or(rest.len());
                let key = &rest[..end];
                if key.is_empty()
                    || !key
                        .chars()
                        .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
                {
                    return Err(format!("`{key}` is not a key (letters, digits, `_`, `-`)"));
                }
                segments.push(Segment::Key(key.to_string()));
                rest = &rest[end..];
                expect_key = false;
            }
        }
        Ok(KeyPath { segments })
    }

    /// Sets the value at this path in `root`, creating missing tables (a scenario that leaves out
    /// `[tracker]` gets one); an index past the end of an array is an error naming the array's length.
    pub fn set(&self, root: &mut toml::Table, value: toml::Value) -> Result<(), String> {
        let mut here = Place::Table(root);
        let last = self.segments.len() - 1;
        for (n, seg) in self.segments.iter().enumerate() {
            let shown = KeyPath {
                segments: self.segments[..=n].to_vec(),
            };
            let slot: &mut toml::Value = match (here, seg) {
                (Place::Table(t), Segment::Key(k)) => {
                    if n == last {
                        if let Some(old) = t.get(k) {
                            same_shape(&shown, old, &value)?;
                        }
                        t.insert(k.clone(), value);
                        return Ok(());
                    }
                    let next_is_index = matches!(self.segments[n + 1], Segment::Index(_));
                    if !t.contains_key(k) {
                        if next_is_index {
                            return Err(format!("`{shown}` is not in the scenario"));
                        }
                        t.insert(k.clone(), toml::Value::Table(toml::Table::new()));
                    }
                    t.get_mut(k).expect("inserted above")
                }
                (Place::Array(a), Segment::Index(i)) => {
                    let len = a.len();
                    if *i >= len {
                        return Err(format!(
                            "`{shown}` does not exist: the scenario's array has {len} entries"
                        ));
                    }
                    if n == last {
                        same_shape(&shown, &a[*i], &value)?;
                        a[*i] = value;
                        return Ok(());
                    }
                    &mut a[*i]
                }
                (Place::Table(_), Segment::Index(_)) => {
                    return Err(format!("`{shown}`: not an array in the scenario"));
                }
                (Place::Array(_), Segment::Key(_)) => {
                    return Err(format!("`{shown}`: an array in the scenario, index it"));
                }
            };
            here = match slot {
                toml::Value::Table(t) => Place::Table(t),
                toml::Value::Array(a) => Place::Array(a),
                other => {
                    return Err(format!(
                        "`{shown}` is a value ({other}) in the scenario, not a table or array"
                    ));
                }
            };
        }
        Ok(())
    }

    /// The value at this path in `root`, if there is one.
    pub fn get<'a>(&self, root: &'a toml::Table) -> Option<&'a toml::Value> {
        let mut value: Option<&toml::Value> = None;
        for seg in &self.segments {
            value = match (value, seg) {
                (None, Segment::Key(k)) => root.get(k),
                (Some(toml::Value::Table(t)), Segment::Key(k)) => t.get(k),
                (Some(toml::Value::Array(a)), Segment::Index(i)) => a.get(*i),
                _ => None,
            };
            value?;
        }
        value
    }
}

/// A table or array of the scenario is replaced only by another: an axis on `robots[1]` with
/// `values = [3]` means `robots[1].count`, and saying so beats the parser's complaint about a type.
fn same_shape(at: &KeyPath, old: &toml::Value, new: &toml::Value) -> Result<(), String> {
    match (old, new) {
        (toml::Value::Table(t), v) if !v.is_table() => {
            let keys: Vec<String> = t.keys().take(6).map(|k| format!("`{at}.{k}`")).collect();
            Err(format!(
                "`{at}` is a table in the scenario, not a single value: set one of its keys ({}{})",
                keys.join(", "),
                if t.len() > keys.len() { ", ..." } else { "" }
            ))
        }
        (toml::Value::Array(a), v) if !v.is_array() => Err(format!(
            "`{at}` is an array of {} in the scenario: set one entry (`{at}[0]`) or give arrays as values",
            a.len()
        )),
        _ => Ok(()),
    }
}

enum Place<'a> {
    Table(&'a mut toml::Table),
    Array(&'a mut Vec<toml::Value>),
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_and_prints() {
        for p in [
            "tracker.latency",
            "pheromones[0].evaporation",
            "robots[1].params.speed",
        ] {
            assert_eq!(KeyPath::parse(p).unwrap().to_string(), p);
        }
        for bad in ["", "[0]", "a..b", "a[x]", "a[1", "a b"] {
            assert!(KeyPath::parse(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn sets_creating_tables_and_refusing_missing_entries() {
        let mut t: toml::Table = "[[robots]]\ncount = 1\n".parse().unwrap();
        KeyPath::parse("tracker.latency")
            .unwrap()
            .set(&mut t, toml::Value::Float(0.1))
            .unwrap();
        assert_eq!(t["tracker"]["latency"].as_float(), Some(0.1));
        KeyPath::parse("robots[0].params.speed")
            .unwrap()
            .set(&mut t, toml::Value::Float(0.2))
            .unwrap();
        assert_eq!(t["robots"][0]["params"]["speed"].as_float(), Some(0.2));
        let e = KeyPath::parse("robots[3].count")
            .unwrap()
            .set(&mut t, toml::Value::Integer(2))
            .unwrap_err();
        assert!(e.contains("robots[3]") && e.contains("1 entries"), "{e}");
        let e = KeyPath::parse("pheromones[0].evaporation")
            .unwrap()
            .set(&mut t, toml::Value::Float(2.0))
            .unwrap_err();
        assert!(e.contains("`pheromones` is not in the scenario"), "{e}");
        let e = KeyPath::parse("robots[0]")
            .unwrap()
            .set(&mut t, toml::Value::Integer(3))
            .unwrap_err();
        assert!(
            e.contains("`robots[0]` is a table") && e.contains("`robots[0].count`"),
            "{e}"
        );
    }
}
