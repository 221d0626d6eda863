//! The sensor samples the twin accepts: each is checked before it reaches the pacer, and a bad
//! one is refused with the reason, logged and counted (the counts go to /diagnostics). Nothing
//! else is lost: a refused sample changes no state.

use std::collections::BTreeMap;
use std::fmt;

/// Why a sample was refused.
#[derive(Debug, Clone, PartialEq)]
pub enum Rejection {
    NonFinite,
    NegativeDischarge(f64),
    /// Above the largest discharge the flume takes, m3/s.
    AbsurdDischarge {
        q: f64,
        limit: f64,
    },
    /// A level outside the flume's height, m.
    LevelOutsideFlume {
        level: f64,
        height: f64,
    },
    /// Older than the sensor's last accepted sample, s.
    OutOfOrder {
        stamp: f64,
        last: f64,
    },
    /// Ahead of the node's clock by more than the tolerance, s.
    FromTheFuture {
        ahead: f64,
    },
    /// A range reading outside the sensor's own bounds (no echo, or too close), m.
    RangeOutOfBounds {
        range: f64,
        min: f64,
        max: f64,
    },
}

impl Rejection {
    /// A short key for the counters in /diagnostics.
    pub fn key(&self) -> &'static str {
        match self {
            Rejection::NonFinite => "non_finite",
            Rejection::NegativeDischarge(_) => "negative_discharge",
            Rejection::AbsurdDischarge { .. } => "absurd_discharge",
            Rejection::LevelOutsideFlume { .. } => "level_outside_flume",
            Rejection::OutOfOrder { .. } => "out_of_order",
            Rejection::FromTheFuture { .. } => "future_stamp",
            Rejection::RangeOutOfBounds { .. } => "range_out_of_bounds",
        }
    }
}

impl fmt::Display for Rejection {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Rejection::NonFinite => write!(f, "not a finite number"),
            Rejection::NegativeDischarge(q) => write!(f, "negative discharge {q} m3/s"),
            Rejection::AbsurdDischarge { q, limit } => {
                write!(f, "discharge {q} m3/s above the flume's limit {limit} m3/s")
            }
            Rejection::LevelOutsideFlume { level, height } => {
                write!(f, "level {level} m outside the flume (0 to {height} m)")
            }
            Rejection::OutOfOrder { stamp, last } => write!(
                f,
                "stamp {stamp:.6} s is older than the last accepted {last:.6} s"
            ),
            Rejection::FromTheFuture { ahead } => {
                write!(f, "stamp {ahead:.3} s ahead of this node's clock")
            }
            Rejection::RangeOutOfBounds { range, min, max } => {
                write!(f, "range {range} m outside the sensor's {min} to {max} m")
            }
        }
    }
}

/// The checks: limits from the case and the node's settings.
#[derive(Debug, Clone)]
pub struct Limits {
    /// The largest discharge the twin takes, m3/s: the solver's limit for the inlet.
    pub max_discharge_m3_per_s: f64,
    /// Flume height, m: a level outside 0..height is a sensor fault.
    pub flume_height_m: f64,
    /// How far ahead of the node's clock a stamp may be (clock skew), s.
    pub future_tolerance_s: f64,
}

impl Limits {
    /// The limits of `case`'s open flume (none on the discharge without one).
    pub fn for_case(case: &flume_solver::Case, future_tolerance_s: f64) -> Limits {
        let vertical = case.dim() - 1;
        Limits {
            max_discharge_m3_per_s: flume_solver::inflow_limit_m3_per_s(case)
                .unwrap_or(f64::INFINITY),
            flume_height_m: case.domain.max_m[vertical] - case.domain.min_m[vertical],
            future_tolerance_s,
        }
    }
}

/// Per-sensor order and the refusal counters.
#[derive(Debug, Clone)]
pub struct InputGate {
    limits: Limits,
    last_stamp: BTreeMap<String, f64>,
    refused: BTreeMap<&'static str, u64>,
}

impl InputGate {
    pub fn new(limits: Limits) -> InputGate {
        InputGate {
            limits,
            last_stamp: BTreeMap::new(),
            refused: BTreeMap::new(),
        }
    }

    /// Refusals so far, by reason.
    pub fn refused(&self) -> &BTreeMap<&'static str, u64> {
        &self.refused
    }

    pub fn refused_total(&self) -> u64 {
        self.refused.values().sum()
    }

    fn order(&self, sensor: &str, stamp: f64, now: f64) -> Result<(), Rejection> {
        if !stamp.is_finite() {
            return Err(Rejection::NonFinite);
        }
        if stamp > now + self.limits.future_tolerance_s {
            return Err(Rejection::FromTheFuture { ahead: stamp - now });
        }
        match self.last_stamp.get(sensor) {
            Some(&last) if stamp < last => Err(Rejection::OutOfOrder { stamp, last }),
            _ => Ok(()),
        }
    }

    fn settle(
        &mut self,
        sensor: &str,
        stamp: f64,
        r: Result<(), Rejection>,
    ) -> Result<(), Rejection> {
        match &r {
            Ok(()) => {
                self.last_stamp.insert(sensor.to_string(), stamp);
            }
            Err(e) => {
                *self.refused.entry(e.key()).or_default() += 1;
                log::warn!("{sensor}: sample at {stamp:.6} s refused: {e}");
            }
        }
        r
    }

    /// Checks a discharge sample (stamp in s, q in m3/s) from sensor `sensor`; `now` is the
    /// node's clock in the same time base.
    pub fn discharge(
        &mut self,
        sensor: &str,
        stamp: f64,
        q: f64,
        now: f64,
    ) -> Result<(), Rejection> {
        let r = self.order(sensor, stamp, now).and_then(|()| {
            if !q.is_finite() {
                Err(Rejection::NonFinite)
            } else if q < 0.0 {
                Err(Rejection::NegativeDischarge(q))
            } else if q > self.limits.max_discharge_m3_per_s {
                Err(Rejection::AbsurdDischarge {
                    q,
                    limit: self.limits.max_discharge_m3_per_s,
                })
            } else {
                Ok(())
            }
        });
        self.settle(sensor, stamp, r)
    }

    /// Checks an ultrasonic gauge's range reading (sensor_msgs/Range: the distance down to the
    /// water from a sensor mounted `mount_m` above the flume floor) and gives the level,
    /// `mount_m - range`.
    pub fn range(
        &mut self,
        sensor: &str,
        stamp: f64,
        range: f64,
        bounds: (f64, f64),
        mount_m: f64,
        now: f64,
    ) -> Result<f64, Rejection> {
        let (min, max) = bounds;
        let r = self.order(sensor, stamp, now).and_then(|()| {
            if !range.is_finite() {
                Err(Rejection::NonFinite)
            } else if range < min || range > max {
                Err(Rejection::RangeOutOfBounds { range, min, max })
            } else {
                Ok(())
            }
        });
        if let Err(e) = r {
            return self.settle(sensor, stamp, Err(e)).map(|()| 0.0);
        }
        let level = mount_m - range;
        self.level(sensor, stamp, level, now).map(|()| level)
    }

    /// Checks a water level sample (m above the flume floor).
    pub fn level(
        &mut self,
        sensor: &str,
        stamp: f64,
        level: f64,
        now: f64,
    ) -> Result<(), Rejection> {
        let r = self.order(sensor, stamp, now).and_then(|()| {
            if !level.is_finite() {
                Err(Rejection::NonFinite)
            } else if !(0.0..=self.limits.flume_height_m).contains(&level) {
                Err(Rejection::LevelOutsideFlume {
                    level,
                    height: self.limits.flume_height_m,
                })
            } else {
                Ok(())
            }
        });
        self.settle(sensor, stamp, r)
    }
}

/// What a gauge sensor said: a level, or an ultrasonic range down to the water.
#[derive(Debug, Clone, Copy)]
pub enum Reading {
    Level(f64),
    Range { range: f64, min: f64, max: f64 },
}

#[derive(Debug, Clone, Copy)]
pub struct GaugeSample {
    pub stamp_s: f64,
    pub reading: Reading,
}

#[cfg(test)]
mod tests {
    use super::*;

    fn gate() -> InputGate {
        InputGate::new(Limits {
            max_discharge_m3_per_s: 0.01,
            flume_height_m: 0.3,
            future_tolerance_s: 0.5,
        })
    }

    #[test]
    fn bad_discharges_are_refused_and_counted_and_change_nothing() {
        let mut g = gate();
        assert_eq!(g.discharge("inflow", 10.0, 5e-4, 10.0), Ok(()));
        assert_eq!(
            g.discharge("inflow", 10.1, f64::NAN, 10.1),
            Err(Rejection::NonFinite)
        );
        assert_eq!(
            g.discharge("inflow", 10.2, -1e-4, 10.2),
            Err(Rejection::NegativeDischarge(-1e-4))
        );
        assert!(matches!(
            g.discharge("inflow", 10.3, 1.0, 10.3),
            Err(Rejection::AbsurdDischarge { .. })
        ));
        // A refused sample does not move the sensor's clock: 10.05 is still after 10.0.
        assert_eq!(g.discharge("inflow", 10.05, 6e-4, 10.4), Ok(()));
        assert!(matches!(
            g.discharge("inflow", 10.0, 6e-4, 10.4),
            Err(Rejection::OutOfOrder { .. })
        ));
        assert!(matches!(
            g.discharge("inflow", 12.0, 6e-4, 10.4),
            Err(Rejection::FromTheFuture { .. })
        ));
        assert_eq!(g.refused_total(), 5);
        for key in [
            "non_finite",
            "negative_discharge",
            "absurd_discharge",
            "out_of_order",
            "future_stamp",
        ] {
            assert_eq!(g.refused().get(key), Some(&1), "{key}");
        }
    }

    #[test]
    fn levels_outside_the_flume_are_refused_and_sensors_keep_their_own_order() {
        let mut g = gate();
        assert_eq!(g.level("p1", 5.0, 0.07, 5.0), Ok(()));
        assert!(matches!(
            g.level("p1", 5.1, 0.5, 5.1),
            Err(Rejection::LevelOutsideFlume { .. })
        ));
        assert!(matches!(
            g.level("p1", 5.2, -0.01, 5.2),
            Err(Rejection::LevelOutsideFlume { .. })
        ));
        // P2's first sample may be older than P1's last.
        assert_eq!(g.level("p2", 4.0, 0.06, 5.2), Ok(()));
        assert_eq!(g.refused().get("level_outside_flume"), Some(&2));
    }

    #[test]
    fn a_range_reading_becomes_the_level_under_the_sensor() {
        let mut g = gate();
        // Mounted 0.25 m above the floor, 0.18 m down to the water: 0.07 m of water.
        let level = g
            .range("p1", 1.0, 0.18, (0.02, 0.4), 0.25, 1.0)
            .expect("valid");
        assert!((level - 0.07).abs() < 1e-12);
        assert!(matches!(
            g.range("p1", 1.1, 0.5, (0.02, 0.4), 0.25, 1.1),
            Err(Rejection::RangeOutOfBounds { .. })
        ));
        assert_eq!(
            g.range("p1", 1.2, f64::INFINITY, (0.02, 0.4), 0.25, 1.2),
            Err(Rejection::NonFinite)
        );
        // A level the flume cannot hold: the sensor mounted above its top reads too short.
        assert!(matches!(
            g.range("p1", 1.3, 0.03, (0.02, 0.4), 0.5, 1.3),
            Err(Rejection::LevelOutsideFlume { .. })
        ));
        assert_eq!(g.refused_total(), 3);
    }
}
