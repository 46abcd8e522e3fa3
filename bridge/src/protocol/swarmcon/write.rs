//! Formats tracker blocks byte for byte as the C position server's `sprintf` calls do, so a twin
//! server can stand in for the real one.

use super::{TrackerEvent, TrackerFrame};
use std::fmt::Write;

/// Which of the servers' header lines to write.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum HeaderForm {
    /// `Detected %i of %i at %ld \n`
    #[default]
    Plain,
    /// `Detected %i of %i at %ld. \n` (the form the reference client parses)
    Dot,
    /// `Detected %i of %i at %ld, %i updated. \n` (CosPhi's `CPositionServer.cpp`)
    Updated,
}

/// Appends `v` as C's `%.3f` prints it (glibc spellings for non-finite values).
pub(crate) fn push_c_f3(out: &mut String, v: f64) {
    if v.is_nan() {
        out.push_str(if v.is_sign_negative() { "-nan" } else { "nan" });
    } else if v.is_infinite() {
        out.push_str(if v < 0.0 { "-inf" } else { "inf" });
    } else {
        // Rust's `{:.3}` rounds the exact binary value half-to-even and keeps the sign of -0.000,
        // as glibc does.
        let _ = write!(out, "{v:.3}");
    }
}

/// `v` as C's `%.3f` prints it.
pub(crate) fn format_c_f3(v: f64) -> String {
    let mut s = String::new();
    push_c_f3(&mut s, v);
    s
}

/// Appends one frame (header and `Robot` lines). `HeaderForm::Updated` writes `frame.updated`, or 0.
pub(crate) fn write_frame(out: &mut String, frame: &TrackerFrame, form: HeaderForm) {
    let _ = write!(
        out,
        "Detected {} of {} at {}",
        frame.found, frame.tracked, frame.t_us
    );
    match form {
        HeaderForm::Plain => out.push_str(" \n"),
        HeaderForm::Dot => out.push_str(". \n"),
        HeaderForm::Updated => {
            let _ = writeln!(out, ", {} updated. ", frame.updated.unwrap_or(0));
        }
    }
    for r in &frame.robots {
        // `%03i`: Rust's sign-aware zero padding prints -1 as `-01`, like C.
        let _ = write!(out, "Robot {:03} ", r.id);
        push_c_f3(out, r.x);
        out.push(' ');
        push_c_f3(out, r.y);
        out.push(' ');
        push_c_f3(out, r.yaw_deg);
        let _ = writeln!(out, " {} ", r.last_seen_us);
    }
}

/// Appends an event line.
pub(crate) fn write_event(out: &mut String, event: TrackerEvent) {
    out.push_str(match event {
        TrackerEvent::Calibrated => "Calibrated\n",
        TrackerEvent::Closed => "Closed\n",
    });
}

/// One whole block as the server sends it: the frame, then `Calibrated` right after a calibration.
pub fn write_block(frame: &TrackerFrame, form: HeaderForm, calibrated: bool) -> String {
    let mut s = String::with_capacity(32 + 48 * frame.robots.len());
    write_frame(&mut s, frame, form);
    if calibrated {
        write_event(&mut s, TrackerEvent::Calibrated);
    }
    s
}
