//! Clocks of the live loop: the host's wall clock, and the offset between a tracker's clock and it.
use std::time::{SystemTime, UNIX_EPOCH};

/// Seconds since the Unix epoch on this machine.
pub(crate) fn epoch_s() -> f64 {
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map(|d| d.as_secs_f64())
        .unwrap_or(0.0)
}

/// Nanoseconds since the Unix epoch on this machine.
pub(crate) fn epoch_ns() -> u64 {
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map(|d| d.as_nanos() as u64)
        .unwrap_or(0)
}

/// Estimates how far a source's clock lags this machine's: the smallest `receipt - source time` seen,
/// which is the offset plus the fastest delivery. The estimate forgets slowly (10 ms a minute), so a
/// clock that steps back is followed.
#[derive(Clone, Copy, Debug, Default)]
pub struct ClockOffset {
    offset: Option<f64>,
    last: f64,
}

impl ClockOffset {
    /// A block stamped `source_t` (source clock, s) arrived at `receipt` (host epoch, s).
    pub fn observe(&mut self, source_t: f64, receipt: f64) {
        let d = receipt - source_t;
        if !d.is_finite() {
            return;
        }
        let forgotten = self
            .offset
            .map(|o| o + (receipt - self.last).max(0.0) * (0.01 / 60.0));
        self.offset = Some(forgotten.map_or(d, |o| o.min(d)));
        self.last = receipt;
    }

    /// The current estimate, s (0 before the first block).
    pub fn offset(&self) -> f64 {
        self.offset.unwrap_or(0.0)
    }

    /// How old, on the host clock at `now` (epoch s), a capture stamped `source_t` is.
    pub fn age(&self, source_t: f64, now: f64) -> f64 {
        (now - (source_t + self.offset())).max(0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_tracker_clock_ahead_by_an_hour_gives_true_ages() {
        let mut c = ClockOffset::default();
        let ahead = 3600.0;
        // Blocks captured every 30 ms, delivered after 5-9 ms.
        for k in 0..100 {
            let capture = 1000.0 + k as f64 * 0.03;
            c.observe(capture + ahead, capture + 0.005 + (k % 5) as f64 * 0.001);
        }
        // Within what the slow forgetting adds over the few blocks since the fastest one.
        assert!(
            (c.offset() - (0.005 - ahead)).abs() < 1e-4,
            "{}",
            c.offset()
        );
        let age = c.age(1000.0 + ahead, 1000.02);
        assert!((age - 0.015).abs() < 1e-4, "{age}");
    }
}
