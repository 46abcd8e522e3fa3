//! The rig plant's gate: real robots are driven only with a current, precise screen calibration.
use crate::{CalibrationLimits, PlantError};
use colcos_bridge::calibrate::RigCalibration;

/// The rig plant drives real robots only with a screen calibration younger than `limits.max_age`
/// whose error is under `limits.max_error_mm`.
pub(super) fn check(cal: &RigCalibration, limits: &CalibrationLimits) -> Result<(), PlantError> {
    let key = "rig.screen_calibration";
    let Some(screen) = &cal.screen else {
        return Err(PlantError::option(
            key,
            "the rig plant needs a screen calibration: run `colcos calibrate screen` and name its file here",
        ));
    };
    if screen.rms_mm.is_nan() || screen.rms_mm > limits.max_error_mm {
        return Err(PlantError::option(
            key,
            format!(
                "its error is {:.2} mm RMS, more than the {} mm allowed: calibrate again",
                screen.rms_mm, limits.max_error_mm
            ),
        ));
    }
    let now = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0.0, |d| d.as_secs_f64());
    match parse_utc(&screen.date) {
        Some(t) if now - t <= limits.max_age => Ok(()),
        Some(t) => Err(PlantError::option(
            key,
            format!(
                "it was measured {} ({:.1} days ago), more than the {:.1} days allowed: calibrate again",
                screen.date,
                (now - t) / 86400.0,
                limits.max_age / 86400.0
            ),
        )),
        None => Err(PlantError::option(
            key,
            format!("its date {:?} is not YYYY-MM-DDTHH:MM:SSZ", screen.date),
        )),
    }
}

/// Seconds since the Unix epoch of a UTC time written `YYYY-MM-DDTHH:MM:SSZ`.
fn parse_utc(s: &str) -> Option<f64> {
    let b = s.as_bytes();
    if b.len() != 20 || b[4] != b'-' || b[7] != b'-' || b[10] != b'T' || b[19] != b'Z' {
        return None;
    }
    let num = |r: std::ops::Range<usize>| s.get(r)?.parse::<i64>().ok();
    let (y, m, d) = (num(0..4)?, num(5..7)?, num(8..10)?);
    let (hh, mm, ss) = (num(11..13)?, num(14..16)?, num(17..19)?);
    if !(1..=12).contains(&m) || !(1..=31).contains(&d) || hh > 23 || mm > 59 || ss > 60 {
        return None;
    }
    // Days from the civil date (Howard Hinnant's algorithm).
    let y = if m <= 2 { y - 1 } else { y };
    let era = y.div_euclid(400);
    let yoe = y - era * 400;
    let doy = (153 * ((m + 9) % 12) + 2) / 5 + d - 1;
    let doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
    let days = era * 146_097 + doe - 719_468;
    Some((days * 86_400 + hh * 3600 + mm * 60 + ss) as f64)
}

#[cfg(test)]
mod tests {
    #[test]
    fn utc_dates_parse() {
        assert_eq!(super::parse_utc("1970-01-01T00:00:00Z"), Some(0.0));
        assert_eq!(
            super::parse_utc("2026-11-24T01:02:03Z"),
            Some(1_795_482_123.0)
        );
        assert_eq!(super::parse_utc("2026-13-01T00:00:00Z"), None);
        assert_eq!(super::parse_utc("yesterday"), None);
    }
}
