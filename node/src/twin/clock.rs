//! The node's time, ROS time in seconds since the epoch: the system clock, or with
//! `use_sim_time:=true` the newest `/clock` message, as a ROS node has it while `ros2 bag play
//! --clock` (or `flume-twin replay --publish`) plays a recorded session. Simulated time that
//! has not started yet has no value: the node then judges no sample and runs no solver chunk.

use std::time::{SystemTime, UNIX_EPOCH};

/// The system clock, s since the epoch.
pub fn system_s() -> f64 {
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map_or(0.0, |d| d.as_secs_f64())
}

#[derive(Debug, Clone, PartialEq)]
pub enum NodeClock {
    System,
    /// The newest `/clock` time, once one came.
    Simulated(Option<f64>),
}

impl NodeClock {
    pub fn new(use_sim_time: bool) -> NodeClock {
        if use_sim_time {
            NodeClock::Simulated(None)
        } else {
            NodeClock::System
        }
    }

    pub fn simulated(&self) -> bool {
        matches!(self, NodeClock::Simulated(_))
    }

    /// Now, or None while simulated time has not started.
    pub fn now(&self) -> Option<f64> {
        match self {
            NodeClock::System => Some(system_s()),
            NodeClock::Simulated(t) => *t,
        }
    }

    /// A `/clock` message at `t` s; true when it went back (a player restarted or looped),
    /// which it follows, as ROS does, and says. Time 0 is ROS's "not started" and, like a
    /// non-finite time, is ignored. The system clock ignores `/clock`.
    pub fn set(&mut self, t: f64) -> bool {
        let NodeClock::Simulated(latest) = self else {
            return false;
        };
        if !(t.is_finite() && t > 0.0) {
            log::warn!("a /clock message at {t} s was ignored");
            return false;
        }
        let back = match *latest {
            None => {
                println!("simulated time started at {t:.3} s (use_sim_time)");
                false
            }
            Some(previous) if t < previous => {
                log::warn!(
                    "/clock went back {:.3} s, from {previous:.3} to {t:.3}: followed",
                    previous - t
                );
                true
            }
            Some(_) => false,
        };
        *latest = Some(t);
        back
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn simulated_time_starts_with_the_first_clock_and_follows_it_back() {
        let mut c = NodeClock::new(true);
        assert_eq!(c.now(), None, "no time before the first /clock");
        assert!(!c.set(0.0));
        assert_eq!(c.now(), None, "time 0 is ROS's not started");
        assert!(!c.set(100.0));
        assert_eq!(c.now(), Some(100.0));
        assert!(!c.set(f64::NAN));
        assert_eq!(c.now(), Some(100.0), "a NaN clock is ignored");
        assert!(!c.set(100.5));
        assert!(c.set(90.0), "a jump back is said");
        assert_eq!(c.now(), Some(90.0), "and followed");
    }

    #[test]
    fn the_system_clock_ignores_clock_messages() {
        let mut c = NodeClock::new(false);
        assert!(!c.set(5.0));
        let now = c.now().expect("the system clock always reads");
        assert!(now > 1.7e9, "seconds since the epoch, got {now}");
    }
}
