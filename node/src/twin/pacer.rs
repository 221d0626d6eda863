//! Pseudo-real time: how far the solver may advance, and which inputs fall in each chunk.
//!
//! Simulated time 0 is the node clock's time at the first event (the first sensor sample, or
//! the start when nothing drives the twin). While sensors speak, the twin runs to the newest
//! sensor stamp; when none has spoken for `stale_after_s`, it runs on the node's clock times
//! the target real-time factor, from where the sensors left it. Every accepted discharge is
//! applied at its own stamp; one that arrives after the solver has passed its stamp is applied
//! at once and counted as late, never dropped.

use std::collections::VecDeque;

/// A stretch for the solver: advance to `to_s`, changing the discharge at each `(t_s, q)`.
#[derive(Debug, Clone, PartialEq)]
pub struct Chunk {
    pub to_s: f64,
    pub inflow: Vec<(f64, f64)>,
}

#[derive(Debug, Clone)]
pub struct Pacer {
    /// Node-clock time of simulated time 0, s.
    origin: Option<f64>,
    /// The newest accepted sensor stamp (node clock), s.
    newest: Option<f64>,
    /// Where the free-running clock starts: (simulated time, node clock).
    anchor: Option<(f64, f64)>,
    pending: VecDeque<(f64, f64)>,
    pub target_rtf: f64,
    pub stale_after_s: f64,
    /// Hold at t = 0 until the first sensor sample (the twin starts with the flume).
    pub wait_for_sensors: bool,
    pub late_inputs: u64,
}

impl Pacer {
    pub fn new(target_rtf: f64, stale_after_s: f64, wait_for_sensors: bool) -> Pacer {
        Pacer {
            origin: None,
            newest: None,
            anchor: None,
            pending: VecDeque::new(),
            target_rtf,
            stale_after_s,
            wait_for_sensors,
            late_inputs: 0,
        }
    }

    /// A new target factor: the free-running clock restarts from where the twin is, so the
    /// change does not rescale the time already run.
    pub fn set_target_rtf(&mut self, rtf: f64) {
        self.target_rtf = rtf;
        self.anchor = None;
    }

    /// Node-clock time of simulated time 0, once fixed.
    pub fn origin(&self) -> Option<f64> {
        self.origin
    }

    /// Simulated time of node-clock time `t`.
    pub fn sim_time_of(&mut self, t: f64) -> f64 {
        t - *self.origin.get_or_insert(t)
    }

    /// A sensor sample stamped `stamp` (node clock) was accepted.
    pub fn heard(&mut self, stamp: f64) {
        self.sim_time_of(stamp);
        self.newest = Some(self.newest.map_or(stamp, |n| n.max(stamp)));
        self.anchor = None;
    }

    /// An accepted discharge `q` stamped `stamp`.
    pub fn inflow(&mut self, stamp: f64, q: f64) {
        self.heard(stamp);
        let t = self.sim_time_of(stamp);
        self.pending.push_back((t, q));
    }

    /// Whether the sensors drive the twin at node-clock time `now`.
    pub fn sensor_driven(&self, now: f64) -> bool {
        self.newest.is_some_and(|n| now - n < self.stale_after_s)
    }

    /// Simulated time the twin should have reached at node-clock time `now`, having reached
    /// `sim_t`.
    pub fn target(&mut self, sim_t: f64, now: f64) -> f64 {
        if self.wait_for_sensors && self.newest.is_none() {
            return sim_t;
        }
        if self.sensor_driven(now) {
            let newest = self.newest.unwrap_or(now);
            return self.sim_time_of(newest).max(sim_t);
        }
        // Fixes the origin when nothing has yet.
        self.sim_time_of(now);
        let (sim0, t0) = *self.anchor.get_or_insert((sim_t, now));
        (sim0 + (now - t0) * self.target_rtf).max(sim_t)
    }

    /// How far the twin is behind where it should be, s of simulated time.
    pub fn lag(&mut self, sim_t: f64, now: f64) -> f64 {
        self.target(sim_t, now) - sim_t
    }

    /// Simulated time 0 is node-clock time `origin` (a replay's first sample, whether the
    /// gate takes it or not).
    pub fn start_at(&mut self, origin: f64) {
        self.origin = Some(origin);
    }

    /// A discharge in force at t = 0: a replay that starts after it was sent.
    pub fn hold(&mut self, q: f64) {
        self.pending.push_back((0.0, q));
    }

    /// One chunk of `len_s` from `sim_t` whatever the sensors say (a paused twin's single
    /// step), with the inputs stamped in it.
    pub fn step(&mut self, sim_t: f64, len_s: f64) -> Chunk {
        self.chunk_to(sim_t, sim_t + len_s)
    }

    /// The chunk from `sim_t` to `to_s` whatever the sensors say (a step, or a replay's
    /// lock-step chunk), with the inputs stamped in it.
    pub fn chunk_to(&mut self, sim_t: f64, to_s: f64) -> Chunk {
        let inflow = self.due(sim_t, to_s);
        // The free-running clock, if it runs, restarts from the chunk's end.
        self.anchor = None;
        Chunk { to_s, inflow }
    }

    /// The discharges stamped up to `to_s`; one stamped before `sim_t` is applied at once.
    fn due(&mut self, sim_t: f64, to_s: f64) -> Vec<(f64, f64)> {
        let mut inflow = Vec::new();
        while let Some(&(t, q)) = self.pending.front() {
            if t > to_s {
                break;
            }
            inflow.push((t.max(sim_t), q));
            self.pending.pop_front();
        }
        inflow
    }

    /// The next chunk from `sim_t`, at most `max_chunk_s` long; None when the twin is where
    /// it should be.
    pub fn next_chunk(&mut self, sim_t: f64, now: f64, max_chunk_s: f64) -> Option<Chunk> {
        let target = self.target(sim_t, now);
        if target <= sim_t + 1e-9 {
            return None;
        }
        let to_s = target.min(sim_t + max_chunk_s);
        let mut inflow = Vec::new();
        while let Some(&(t, q)) = self.pending.front() {
            if t > to_s {
                break;
            }
            if t < sim_t {
                self.late_inputs += 1;
                log::warn!(
                    "a discharge stamped for t = {t:.3} s arrived after the twin passed it ({sim_t:.3} s): applied now"
                );
            }
            inflow.push((t.max(sim_t), q));
            self.pending.pop_front();
        }
        Some(Chunk { to_s, inflow })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sensors_drive_the_twin_to_their_newest_stamp_in_chunks() {
        let mut p = Pacer::new(1.0, 2.0, false);
        p.inflow(100.0, 5e-4);
        p.heard(100.4);
        p.inflow(100.7, 6e-4);
        // Simulated time 0 is the first stamp; the twin may run to the newest, 0.7 s.
        let c = p.next_chunk(0.0, 100.8, 0.5).expect("a chunk");
        assert_eq!(
            c,
            Chunk {
                to_s: 0.5,
                inflow: vec![(0.0, 5e-4)]
            }
        );
        let c = p.next_chunk(0.5, 100.8, 0.5).expect("a chunk");
        assert!((c.to_s - 0.7).abs() < 1e-9 && c.inflow.len() == 1, "{c:?}");
        assert!((c.inflow[0].0 - 0.7).abs() < 1e-9);
        assert_eq!(p.next_chunk(0.7, 100.9, 0.5), None, "caught up");
        assert!(p.sensor_driven(101.0));
    }

    #[test]
    fn silent_sensors_hand_over_to_the_clock_times_the_factor() {
        let mut p = Pacer::new(0.5, 1.0, false);
        p.inflow(10.0, 5e-4);
        p.heard(10.2);
        // At 11.5 the newest stamp is 1.3 s old: stale. The clock runs on from t = 0.2 s.
        assert!(!p.sensor_driven(11.5));
        assert!((p.target(0.2, 11.5) - 0.2).abs() < 1e-9);
        assert!((p.target(0.2, 13.5) - 1.2).abs() < 1e-9, "0.2 + 2 s x 0.5");
        // A new sample takes over again.
        p.heard(13.6);
        assert!((p.target(1.2, 13.7) - 3.6).abs() < 1e-9);
    }

    #[test]
    fn with_no_sensors_the_clock_runs_from_the_start() {
        let mut p = Pacer::new(2.0, 1.0, false);
        assert_eq!(p.next_chunk(0.0, 50.0, 1.0), None, "t = 0 at the start");
        let c = p.next_chunk(0.0, 50.25, 1.0).expect("runs");
        assert!((c.to_s - 0.5).abs() < 1e-9);
        assert!((p.lag(0.1, 50.25) - 0.4).abs() < 1e-9);
    }

    #[test]
    fn waiting_for_sensors_holds_the_twin_at_zero_until_the_first_sample() {
        let mut p = Pacer::new(1.0, 1.0, true);
        assert_eq!(p.next_chunk(0.0, 50.0, 1.0), None);
        assert_eq!(p.next_chunk(0.0, 60.0, 1.0), None, "still no sensor");
        assert_eq!(p.origin(), None);
        p.inflow(61.0, 1e-4);
        p.heard(61.5);
        assert_eq!(p.origin(), Some(61.0), "t = 0 is the first sample");
        let c = p.next_chunk(0.0, 61.5, 1.0).expect("runs");
        assert!((c.to_s - 0.5).abs() < 1e-9);
    }

    #[test]
    fn a_new_target_factor_applies_from_now_on() {
        let mut p = Pacer::new(1.0, 1.0, false);
        assert!((p.target(0.0, 10.0) - 0.0).abs() < 1e-9);
        assert!((p.target(0.0, 12.0) - 2.0).abs() < 1e-9);
        // Reached 2 s at 12 s; at factor 0.25 the next 4 s of wall time are 1 s simulated.
        p.set_target_rtf(0.25);
        assert!((p.target(2.0, 12.0) - 2.0).abs() < 1e-9);
        assert!((p.target(2.0, 16.0) - 3.0).abs() < 1e-9);
    }

    #[test]
    fn a_late_discharge_is_applied_at_once_not_dropped() {
        let mut p = Pacer::new(1.0, 5.0, false);
        p.inflow(0.0, 1e-4);
        p.heard(2.0);
        let _ = p.next_chunk(0.0, 2.0, 5.0);
        // Stamped 1.5 s, accepted after the twin reached 2 s.
        p.inflow(1.5, 2e-4);
        p.heard(2.5);
        let c = p.next_chunk(2.0, 2.5, 5.0).expect("runs");
        assert_eq!(c.inflow, vec![(2.0, 2e-4)]);
        assert_eq!(p.late_inputs, 1);
    }
}
