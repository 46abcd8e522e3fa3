//! The client-to-server `Calibrate` command that starts the position server's auto-calibration.

use super::write::format_c_f3;
use thiserror::Error;

/// `Calibrate %i %.3f %.3f %.3f %.3f %.3f \n`: all lengths in metres.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Calibrate {
    pub robots: i32,
    pub field_length: f64,
    pub field_width: f64,
    pub camera_height: f64,
    pub robot_diameter: f64,
    pub robot_height: f64,
}

#[derive(Clone, Debug, Error, PartialEq)]
#[error("`Calibrate` command: {field} {reason}")]
pub struct CalibrateError {
    pub field: &'static str,
    pub reason: &'static str,
}

const FIELDS: [&str; 5] = [
    "field length",
    "field width",
    "camera height",
    "robot diameter",
    "robot height",
];

impl Calibrate {
    fn lengths(&self) -> [f64; 5] {
        [
            self.field_length,
            self.field_width,
            self.camera_height,
            self.robot_diameter,
            self.robot_height,
        ]
    }

    /// Checks what the server would need to calibrate: a robot count and positive finite lengths.
    pub fn validate(&self) -> Result<(), CalibrateError> {
        if !(0..=super::MAX_SLOTS as i32).contains(&self.robots) {
            return Err(CalibrateError {
                field: "robots",
                reason: "must be between 0 and 1024",
            });
        }
        for (v, field) in self.lengths().iter().zip(FIELDS) {
            if !(v.is_finite() && *v > 0.0 && *v < 1000.0) {
                return Err(CalibrateError {
                    field,
                    reason: "must be a positive number of metres",
                });
            }
        }
        Ok(())
    }

    /// The command line exactly as the reference client writes it.
    pub fn encode(&self) -> Result<String, CalibrateError> {
        self.validate()?;
        let mut s = format!("Calibrate {}", self.robots);
        for v in self.lengths() {
            s.push(' ');
            s.push_str(&format_c_f3(v));
        }
        s.push_str(" \n");
        Ok(s)
    }

    /// Parses one command line (as the server's `sscanf` would, but strictly).
    pub fn parse(line: &[u8]) -> Result<Calibrate, CalibrateError> {
        let bad = |field, reason| CalibrateError { field, reason };
        let s = std::str::from_utf8(line).map_err(|_| bad("line", "is not UTF-8"))?;
        let mut it = s.split_ascii_whitespace();
        if it.next() != Some("Calibrate") {
            return Err(bad("keyword", "`Calibrate` expected"));
        }
        let robots = it
            .next()
            .and_then(|t| t.parse().ok())
            .ok_or(bad("robots", "must be an integer"))?;
        let mut v = [0.0f64; 5];
        for (slot, field) in v.iter_mut().zip(FIELDS) {
            *slot = it
                .next()
                .and_then(|t| t.parse().ok())
                .ok_or(bad(field, "must be a number"))?;
        }
        if it.next().is_some() {
            return Err(bad("end of line", "expected"));
        }
        let c = Calibrate {
            robots,
            field_length: v[0],
            field_width: v[1],
            camera_height: v[2],
            robot_diameter: v[3],
            robot_height: v[4],
        };
        c.validate()?;
        Ok(c)
    }
}
