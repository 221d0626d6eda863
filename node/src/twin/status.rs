//! The twin's `/diagnostics`, once a second: how fast it runs against the sensors, what it
//! refused and why, and a line on the terminal every ten seconds for whoever started it.

use super::Twin;
use super::solver_thread::Report;
use flume_msgs::builtin_interfaces::Time;
use flume_msgs::diagnostic_msgs::{DiagnosticArray, DiagnosticStatus, KeyValue};
use flume_msgs::std_msgs::Header;
use std::time::Instant;

/// What the twin counts since it started.
#[derive(Debug, Clone, Default)]
pub struct Counters {
    pub undecodable: u64,
    pub solver_refused: u64,
    /// Samples that came before simulated time started.
    pub before_clock: u64,
    pub published_outputs: u64,
    pub decimated_outputs: u64,
    /// Particle frames sent to visualisers and skipped.
    pub frames_sent: u64,
    pub frames_skipped: u64,
}

/// Simulated time, steps and solver time over the last diagnostics period.
pub struct Period {
    started: Instant,
    sim_t0: f64,
    steps: u64,
    busy_s: f64,
}

impl Period {
    pub fn new(sim_t: f64) -> Period {
        Period {
            started: Instant::now(),
            sim_t0: sim_t,
            steps: 0,
            busy_s: 0.0,
        }
    }

    pub fn add(&mut self, report: &Report) {
        self.steps += report.steps;
        self.busy_s += report.wall_s;
    }

    /// (achieved real-time factor, steps per second, fraction of the time the solver ran)
    /// since the last call.
    fn take(&mut self, sim_t: f64) -> (f64, f64, f64) {
        let wall = self.started.elapsed().as_secs_f64().max(1e-9);
        let out = (
            (sim_t - self.sim_t0) / wall,
            self.steps as f64 / wall,
            self.busy_s / wall,
        );
        *self = Period::new(sim_t);
        out
    }
}

impl Twin {
    /// The twin's status for `/diagnostics`, once a second.
    pub fn status(&mut self) -> DiagnosticArray {
        let now = self.clock.now();
        let sim_t = self.sim_t;
        let lag = now.map_or(0.0, |now| self.pacer.lag(sim_t, now));
        let (rtf, step_rate, busy) = self.period.take(sim_t);
        self.status_count += 1;
        if self.status_count.is_multiple_of(10) {
            self.say_status(lag);
        }
        let stale: Vec<&str> = self
            .options
            .gauge_names
            .iter()
            .zip(&self.readings)
            .filter(|(_, r)| r.stale(now, self.settings.stale_after_s))
            .map(|(n, _)| n.as_str())
            .collect();
        let values = self.values(now, (rtf, step_rate, busy), lag, &stale);
        let behind = lag > 1.0;
        let level = if behind || !stale.is_empty() {
            DiagnosticStatus::WARN
        } else {
            DiagnosticStatus::OK
        };
        let message = match (behind, stale.is_empty()) {
            (true, _) => format!("{lag:.1} s behind the sensors: outputs decimated"),
            (false, false) => format!("stale sensors: {}", stale.join(", ")),
            (false, true) => "running".to_string(),
        };
        let stamp = Time::from_secs_f64(now.unwrap_or(0.0)).unwrap_or_default();
        DiagnosticArray {
            header: Header {
                stamp,
                frame_id: String::new(),
            },
            status: vec![DiagnosticStatus {
                level,
                name: format!("{}: twin", self.options.node_name),
                message,
                hardware_id: self.solver.adapter.clone(),
                values: values
                    .into_iter()
                    .map(|(k, v)| KeyValue {
                        key: k.to_string(),
                        value: v,
                    })
                    .collect(),
            }],
        }
    }

    /// The key-value pairs of the twin's status; `rates` is (achieved real-time factor, steps
    /// per second, the solver's busy fraction) over the last period.
    fn values(
        &self,
        now: Option<f64>,
        rates: (f64, f64, f64),
        lag: f64,
        stale: &[&str],
    ) -> Vec<(&'static str, String)> {
        let sim_t = self.sim_t;
        let (rtf, step_rate, busy) = rates;
        let c = &self.counters;
        let flume = self.last_obs.flume.as_ref();
        let mut values = vec![
            ("sim_time_s", format!("{sim_t:.6}")),
            ("real_time_factor", format!("{rtf:.4}")),
            (
                "target_real_time_factor",
                format!("{}", self.settings.target_rtf),
            ),
            ("lag_s", format!("{lag:.3}")),
            ("step_rate_hz", format!("{step_rate:.1}")),
            ("particles", self.solver.particles.to_string()),
            ("adapter", self.solver.adapter.clone()),
            ("solver_busy_fraction", format!("{busy:.3}")),
            (
                "sensor_driven",
                now.is_some_and(|now| self.pacer.sensor_driven(now))
                    .to_string(),
            ),
            (
                "clock",
                if self.clock.simulated() {
                    "/clock"
                } else {
                    "system"
                }
                .to_string(),
            ),
            ("inputs_before_clock", c.before_clock.to_string()),
            ("paused", self.paused.to_string()),
            ("stale_sensors", stale.join(",")),
            ("rejected_inputs", self.gate.refused_total().to_string()),
            ("undecodable_inputs", c.undecodable.to_string()),
            ("solver_refused_inflows", c.solver_refused.to_string()),
            ("late_inputs", self.pacer.late_inputs.to_string()),
            ("published_outputs", c.published_outputs.to_string()),
            ("decimated_outputs", c.decimated_outputs.to_string()),
            ("recoveries", self.last_obs.recoveries.to_string()),
            (
                "excluded_particles",
                flume.map_or(0, |f| f.excluded_particles).to_string(),
            ),
            (
                "inlet_blocked_spots",
                flume.map_or(0, |f| f.blocked_particles).to_string(),
            ),
            (
                "bed_pores_particles",
                flume.map_or(0, |f| f.soaked_particles).to_string(),
            ),
            ("particle_frames_sent", c.frames_sent.to_string()),
            ("particle_frames_skipped", c.frames_skipped.to_string()),
        ];
        for (k, n) in self.gate.refused() {
            values.push((k, n.to_string()));
        }
        values
    }

    /// A line on the terminal, for whoever started the twin by hand.
    fn say_status(&mut self, lag: f64) {
        let sim_t = self.sim_t;
        let (rtf, _, _) = self.line_period.take(sim_t);
        let levels: Vec<String> = self
            .options
            .gauge_names
            .iter()
            .zip(&self.last_obs.gauges)
            .map(|(n, g)| {
                let level = g.level_m.map_or("dry".into(), |l| format!("{l:.4} m"));
                format!("{n} {level}")
            })
            .collect();
        let eroded = self.last_obs.flume.as_ref().map_or(0.0, |f| f.eroded_kg);
        println!(
            "t = {sim_t:.2} s, {rtf:.3} x real time, {lag:.1} s behind; {}; eroded {eroded:.4} kg",
            levels.join(", ")
        );
    }
}
