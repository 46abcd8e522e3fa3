//! Parses one line of the position server's stream into a typed value, strictly: every field is
//! checked and an error names it.

use super::{MAX_LINE, MAX_SLOTS};
use thiserror::Error;

/// Coordinates beyond this many metres are not a real arena and are rejected.
pub(crate) const MAX_COORD_M: f64 = 1000.0;
/// Yaw beyond this many degrees is rejected (the server prints within +-180).
pub(crate) const MAX_YAW_DEG: f64 = 3600.0;

/// One parsed line.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TrackerLine {
    /// `Detected %i of %i at %ld[.|, %i updated.] `
    Header {
        found: i32,
        tracked: i32,
        t_us: i64,
        updated: Option<i32>,
    },
    /// `Robot %03i %.3f %.3f %.3f %ld `
    Robot {
        id: i32,
        x: f64,
        y: f64,
        yaw_deg: f64,
        last_seen_us: i64,
    },
    Calibrated,
    Closed,
    /// A blank line: ignored.
    Empty,
}

/// What was wrong with a line or with the order of lines.
#[derive(Clone, Debug, Error, PartialEq)]
pub enum TrackerError {
    #[error("line longer than {MAX_LINE} bytes dropped")]
    TooLong,
    #[error("line is not valid UTF-8")]
    NotUtf8,
    #[error("unknown line {0:?}")]
    Unknown(String),
    #[error("`{line}` line: {field} {reason} (got {text:?})")]
    Field {
        line: &'static str,
        field: &'static str,
        reason: &'static str,
        text: String,
    },
    #[error("`Robot` line outside a block")]
    OrphanRobot,
    #[error("block cut short after {got} of {expected} `Robot` lines")]
    Truncated { got: usize, expected: usize },
}

/// Short copy of bad input for an error message (never the whole 4 KiB line).
fn snippet(s: &str) -> String {
    s.chars().take(64).collect()
}

fn field_err(
    line: &'static str,
    field: &'static str,
    reason: &'static str,
    text: &str,
) -> TrackerError {
    TrackerError::Field {
        line,
        field,
        reason,
        text: snippet(text),
    }
}

fn int<T: std::str::FromStr>(
    line: &'static str,
    field: &'static str,
    tok: Option<&str>,
) -> Result<T, TrackerError> {
    let tok = tok.ok_or_else(|| field_err(line, field, "missing", ""))?;
    tok.parse()
        .map_err(|_| field_err(line, field, "is not an integer", tok))
}

/// An integer whose only allowed negative value is the sentinel -1; below it the error gives
/// `negative` (which says what -1 means).
fn int_or_minus_one<T: std::str::FromStr + PartialOrd + From<i8>>(
    line: &'static str,
    field: &'static str,
    tok: Option<&str>,
    negative: &'static str,
) -> Result<T, TrackerError> {
    let v: T = int(line, field, tok)?;
    if v < T::from(-1) {
        return Err(field_err(line, field, negative, tok.unwrap_or("")));
    }
    Ok(v)
}

/// A `%.3f` number: digits, one optional leading minus and a dot; no exponent, `nan` or `inf`.
fn decimal(
    line: &'static str,
    field: &'static str,
    tok: Option<&str>,
    limit: f64,
) -> Result<f64, TrackerError> {
    let tok = tok.ok_or_else(|| field_err(line, field, "missing", ""))?;
    let digits = tok.strip_prefix('-').unwrap_or(tok);
    if digits.is_empty() || !digits.bytes().all(|b| b.is_ascii_digit() || b == b'.') {
        return Err(field_err(line, field, "is not a decimal number", tok));
    }
    let v: f64 = tok
        .parse()
        .map_err(|_| field_err(line, field, "is not a decimal number", tok))?;
    if !v.is_finite() || v.abs() > limit {
        return Err(field_err(line, field, "is out of range", tok));
    }
    Ok(v)
}

fn expect(line: &'static str, word: &'static str, tok: Option<&str>) -> Result<(), TrackerError> {
    match tok {
        Some(t) if t == word => Ok(()),
        other => Err(field_err(
            line,
            word,
            "keyword expected",
            other.unwrap_or(""),
        )),
    }
}

/// Nothing may follow a line's last field.
fn end_of_line(line: &'static str, tok: Option<&str>) -> Result<(), TrackerError> {
    match tok {
        Some(extra) => Err(field_err(line, "end of line", "expected", extra)),
        None => Ok(()),
    }
}

fn slot_count(field: &'static str, tok: Option<&str>) -> Result<i32, TrackerError> {
    let n: i32 = int("Detected", field, tok)?;
    if !(0..=MAX_SLOTS as i32).contains(&n) {
        return Err(field_err(
            "Detected",
            field,
            "is out of range",
            tok.unwrap_or(""),
        ));
    }
    Ok(n)
}

fn parse_header(s: &str) -> Result<TrackerLine, TrackerError> {
    const L: &str = "Detected";
    let mut it = s.split_ascii_whitespace();
    expect(L, "Detected", it.next())?;
    let found = slot_count("found", it.next())?;
    expect(L, "of", it.next())?;
    let tracked = slot_count("tracked", it.next())?;
    expect(L, "at", it.next())?;
    let time_tok = it
        .next()
        .ok_or_else(|| field_err(L, "time", "missing", ""))?;
    let (digits, sep) = match time_tok.as_bytes().last() {
        Some(b'.') => (&time_tok[..time_tok.len() - 1], Some('.')),
        Some(b',') => (&time_tok[..time_tok.len() - 1], Some(',')),
        _ => (time_tok, None),
    };
    let t_us: i64 = int(L, "time", Some(digits))?;
    if t_us < 0 {
        return Err(field_err(L, "time", "is negative", time_tok));
    }
    let updated = if sep == Some(',') {
        let n: i32 = int(L, "updated", it.next())?;
        if n < 0 {
            return Err(field_err(L, "updated", "is negative", &n.to_string()));
        }
        match it.next() {
            Some("updated." | "updated") => {}
            other => {
                return Err(field_err(
                    L,
                    "updated.",
                    "keyword expected",
                    other.unwrap_or(""),
                ));
            }
        }
        Some(n)
    } else {
        None
    };
    end_of_line(L, it.next())?;
    Ok(TrackerLine::Header {
        found,
        tracked,
        t_us,
        updated,
    })
}

fn parse_robot(s: &str) -> Result<TrackerLine, TrackerError> {
    const L: &str = "Robot";
    let mut it = s.split_ascii_whitespace();
    expect(L, "Robot", it.next())?;
    let id: i32 = int_or_minus_one(
        L,
        "id",
        it.next(),
        "is negative (only -1 means unidentified)",
    )?;
    let x = decimal(L, "x", it.next(), MAX_COORD_M)?;
    let y = decimal(L, "y", it.next(), MAX_COORD_M)?;
    let yaw_deg = decimal(L, "yaw", it.next(), MAX_YAW_DEG)?;
    let last_seen_us: i64 = int_or_minus_one(
        L,
        "last-seen time",
        it.next(),
        "is negative (only -1 means never seen)",
    )?;
    end_of_line(L, it.next())?;
    Ok(TrackerLine::Robot {
        id,
        x,
        y,
        yaw_deg,
        last_seen_us,
    })
}

/// Parses one line (without its `\n`).
pub fn parse_line(bytes: &[u8]) -> Result<TrackerLine, TrackerError> {
    let s = std::str::from_utf8(bytes).map_err(|_| TrackerError::NotUtf8)?;
    let s = s.trim_ascii();
    if s.is_empty() {
        Ok(TrackerLine::Empty)
    } else if s.starts_with("Robot ") {
        parse_robot(s)
    } else if s.starts_with("Detected ") {
        parse_header(s)
    } else if s == "Calibrated" {
        Ok(TrackerLine::Calibrated)
    } else if s == "Closed" {
        Ok(TrackerLine::Closed)
    } else {
        Err(TrackerError::Unknown(snippet(s)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn negative_coordinates_and_unidentified_id() {
        let l = parse_line(b"Robot -01 -0.250 -1.500 -179.999 -1 ").unwrap();
        assert_eq!(
            l,
            TrackerLine::Robot {
                id: -1,
                x: -0.25,
                y: -1.5,
                yaw_deg: -179.999,
                last_seen_us: -1
            }
        );
    }

    #[test]
    fn rejects_nan_and_exponents() {
        assert!(parse_line(b"Robot 001 nan 0.000 0.000 5 ").is_err());
        assert!(parse_line(b"Robot 001 1e3 0.000 0.000 5 ").is_err());
        assert!(parse_line(b"Robot 001 0.000 0.000 0.000 -5 ").is_err());
    }
}
