//! JSON pose messages: one object per UDP datagram or per line,
//! `{"id": 3, "x": 0.5, "y": 0.2, "heading": 1.57, "t": 12.04}` with x, y in metres and heading in
//! radians in the simulator's frame, t in seconds. Validation is strict and errors name the field.

use serde_json::{Map, Value};
use thiserror::Error;

/// One robot's pose from a JSON feed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JsonPose {
    pub id: u32,
    pub x: f64,
    pub y: f64,
    pub heading: f64,
    pub t: f64,
}

#[derive(Clone, Debug, Error, PartialEq)]
pub enum PoseJsonError {
    #[error("pose message is not JSON: {0}")]
    Syntax(String),
    #[error("pose message must be a JSON object")]
    NotObject,
    #[error("pose message: field `{0}` is missing")]
    Missing(&'static str),
    #[error("pose message: unknown field `{0}`")]
    Unknown(String),
    #[error("pose message: field `{field}` {reason} (got {value})")]
    Invalid {
        field: &'static str,
        reason: &'static str,
        value: String,
    },
}

const FIELDS: [&str; 5] = ["id", "x", "y", "heading", "t"];
/// Coordinates beyond this many metres are rejected as nonsense.
const MAX_COORD_M: f64 = 1000.0;

fn short(v: &Value) -> String {
    let mut s = v.to_string();
    s.truncate(40);
    s
}

fn number(obj: &Map<String, Value>, field: &'static str) -> Result<f64, PoseJsonError> {
    let v = obj.get(field).ok_or(PoseJsonError::Missing(field))?;
    let x = v.as_f64().ok_or_else(|| PoseJsonError::Invalid {
        field,
        reason: "must be a number",
        value: short(v),
    })?;
    // serde_json never yields NaN or infinity, but a huge literal still has to be refused.
    if !x.is_finite() {
        return Err(PoseJsonError::Invalid {
            field,
            reason: "must be finite",
            value: short(v),
        });
    }
    Ok(x)
}

fn bounded(
    obj: &Map<String, Value>,
    field: &'static str,
    lo: f64,
    hi: f64,
    reason: &'static str,
) -> Result<f64, PoseJsonError> {
    let x = number(obj, field)?;
    if !(lo..=hi).contains(&x) {
        return Err(PoseJsonError::Invalid {
            field,
            reason,
            value: x.to_string(),
        });
    }
    Ok(x)
}

impl JsonPose {
    /// Parses one message (a datagram or a line; surrounding whitespace is allowed).
    pub fn parse(bytes: &[u8]) -> Result<JsonPose, PoseJsonError> {
        let v: Value =
            serde_json::from_slice(bytes).map_err(|e| PoseJsonError::Syntax(e.to_string()))?;
        let Value::Object(obj) = v else {
            return Err(PoseJsonError::NotObject);
        };
        if let Some(k) = obj.keys().find(|k| !FIELDS.contains(&k.as_str())) {
            return Err(PoseJsonError::Unknown(k.chars().take(40).collect()));
        }
        let idv = obj.get("id").ok_or(PoseJsonError::Missing("id"))?;
        let id = idv
            .as_u64()
            .and_then(|n| u32::try_from(n).ok())
            .ok_or_else(|| PoseJsonError::Invalid {
                field: "id",
                reason: "must be a non-negative integer",
                value: short(idv),
            })?;
        let range = "must be within +-1000 m";
        Ok(JsonPose {
            id,
            x: bounded(&obj, "x", -MAX_COORD_M, MAX_COORD_M, range)?,
            y: bounded(&obj, "y", -MAX_COORD_M, MAX_COORD_M, range)?,
            heading: bounded(&obj, "heading", -1e3, 1e3, "must be radians within +-1000")?,
            t: bounded(&obj, "t", 0.0, 1e12, "must be non-negative seconds")?,
        })
    }

    /// Parses a buffer holding one message per line; blank lines are skipped.
    pub fn parse_lines(bytes: &[u8]) -> Vec<Result<JsonPose, PoseJsonError>> {
        bytes
            .split(|&b| b == b'\n')
            .filter(|l| !l.trim_ascii().is_empty())
            .map(JsonPose::parse)
            .collect()
    }

    /// The message as one JSON object (no trailing newline).
    pub fn to_json(&self) -> String {
        serde_json::json!({"id": self.id, "x": self.x, "y": self.y, "heading": self.heading, "t": self.t})
            .to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_and_round_trips() {
        let p =
            JsonPose::parse(br#" {"id":3,"x":-0.5,"y":0.25,"heading":1.5,"t":12.04} "#).unwrap();
        assert_eq!(
            p,
            JsonPose {
                id: 3,
                x: -0.5,
                y: 0.25,
                heading: 1.5,
                t: 12.04
            }
        );
        assert_eq!(JsonPose::parse(p.to_json().as_bytes()).unwrap(), p);
    }

    #[test]
    fn errors_name_the_field() {
        let e = |s: &str| JsonPose::parse(s.as_bytes()).unwrap_err().to_string();
        assert!(e(r#"{"x":0,"y":0,"heading":0,"t":0}"#).contains("`id`"));
        assert!(e(r#"{"id":-1,"x":0,"y":0,"heading":0,"t":0}"#).contains("`id`"));
        assert!(e(r#"{"id":1,"x":"a","y":0,"heading":0,"t":0}"#).contains("`x`"));
        assert!(e(r#"{"id":1,"x":0,"y":1e300,"heading":0,"t":0}"#).contains("`y`"));
        assert!(e(r#"{"id":1,"x":0,"y":0,"heading":0,"t":-1}"#).contains("`t`"));
        assert!(e(r#"{"id":1,"x":0,"y":0,"heading":0,"t":0,"z":1}"#).contains("`z`"));
        assert!(e("[1,2]").contains("object"));
        assert!(e("{").contains("not JSON"));
    }

    #[test]
    fn lines() {
        let r =
            JsonPose::parse_lines(b"{\"id\":1,\"x\":0,\"y\":0,\"heading\":0,\"t\":0}\n\nnope\n");
        assert_eq!(r.len(), 2);
        assert!(r[0].is_ok() && r[1].is_err());
    }
}
