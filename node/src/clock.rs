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

    /// A `/clock` message at `t` s. A clock that goes back (a player restarted or looped) is
    /// followed, as ROS does, and said; a non-finite one is ignored. The system clock ignores
    /// `/clock`.
    pub fn set(&mut self, t: f64) {
        let NodeClock::Simulated(latest) = self else {
            return;
        };
        if !t.is_finite() {
            log::warn!("a /clock message with a non-finite time was ignored");
            return;
        }
        match *latest {
            None => println!("simulated time started at {t:.3} s (use_sim_time)"),
            Some(previous) if t < previous => log::warn!(
                "/clock went back {:.3} s, from {previous:.3} to {t:.3}: followed",
                previous - t
            ),
            Some(_) => {}
        }
        *latest = Some(t);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn simulated_time_starts_with_the_first_clock_and_follows_it_back() {
        let mut c = NodeClock::new(true);
        assert_eq!(c.now(), None, "no time before the first /clock");
        c.set(100.0);
        assert_eq!(c.now(), Some(100.0));
        c.set(f64::NAN);
        assert_eq!(c.now(), Some(100.0), "a NaN clock is ignored");
        c.set(90.0);
        assert_eq!(c.now(), Some(90.0), "a clock that went back is followed");
    }

    #[test]
    fn the_system_clock_ignores_clock_messages() {
        let mut c = NodeClock::new(false);
        c.set(5.0);
        let now = c.now().expect("the system clock always reads");
        assert!(now > 1.7e9, "seconds since the epoch, got {now}");
    }
}
