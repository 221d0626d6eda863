//! What the gauges said: each gauge's accepted levels, read at the time of an output, and
//! whether a gauge has gone quiet.

use std::collections::VecDeque;

/// A gauge's accepted readings, oldest first, from the one in force at the last output on.
#[derive(Debug, Clone, Default)]
pub struct Readings(VecDeque<(f64, f64)>);

impl Readings {
    pub fn push(&mut self, stamp_s: f64, level_m: f64) {
        self.0.push_back((stamp_s, level_m));
    }

    /// The newest stamp heard, s.
    pub fn newest(&self) -> Option<f64> {
        self.0.back().map(|r| r.0)
    }

    /// Whether the gauge has said nothing for more than `after_s` at time `now`; a gauge
    /// never heard, or a time that has not started, is stale.
    pub fn stale(&self, now: Option<f64>, after_s: f64) -> bool {
        match (self.newest(), now) {
            (Some(t), Some(now)) => now - t > after_s,
            _ => true,
        }
    }

    /// The level in force at `t` (the last reading stamped at or before it), forgetting the
    /// readings it supersedes: outputs come in time order.
    pub fn at(&mut self, t: f64) -> Option<f64> {
        while self.0.len() > 1 && self.0[1].0 <= t {
            self.0.pop_front();
        }
        self.0.front().filter(|r| r.0 <= t).map(|r| r.1)
    }
}

/// Each gauge's level in force at `t`, and whether it is stale at `now`.
pub fn compared_at(
    readings: &mut [Readings],
    t: f64,
    now: Option<f64>,
    after_s: f64,
) -> (Vec<Option<f64>>, Vec<bool>) {
    let stale = readings.iter().map(|r| r.stale(now, after_s)).collect();
    let at = readings.iter_mut().map(|r| r.at(t)).collect();
    (at, stale)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_gauge_is_compared_with_its_reading_at_the_output_time() {
        let mut r = Readings::default();
        assert_eq!(r.at(1.0), None, "no reading yet");
        r.push(1.0, 0.07);
        r.push(1.2, 0.08);
        r.push(1.4, 0.09);
        assert_eq!(r.at(0.5), None, "before the first reading");
        assert_eq!(r.at(1.1), Some(0.07));
        assert_eq!(r.at(1.3), Some(0.08));
        assert_eq!(r.newest(), Some(1.4));
        assert_eq!(r.at(2.0), Some(0.09));
        assert_eq!(r.0.len(), 1, "superseded readings are forgotten");
    }

    #[test]
    fn a_gauge_quiet_for_longer_than_the_limit_is_stale() {
        let mut r = Readings::default();
        assert!(r.stale(Some(1.0), 2.0), "never heard");
        r.push(1.0, 0.07);
        assert!(r.stale(None, 2.0), "time has not started");
        assert!(!r.stale(Some(3.0), 2.0));
        assert!(r.stale(Some(3.5), 2.0));
        let mut gauges = vec![r, Readings::default()];
        let (at, stale) = compared_at(&mut gauges, 1.5, Some(3.5), 2.0);
        assert_eq!(at, vec![Some(0.07), None]);
        assert_eq!(stale, vec![true, true]);
    }
}
