//! The twin's rules, apart from any transport: which samples it takes (the gate), how far the
//! solver may run (the pacer, on the node's clock), the gauges' readings, the settings, and
//! the messages its observations become. [`Twin`] holds them all; whatever drives it (the ROS
//! node, a recorded session) calls one method per event and sends what comes back.

pub mod clock;
pub mod gate;
pub mod messages;
pub mod pacer;
pub mod readings;
pub mod samples;
pub mod settings;
pub mod solver_thread;
pub mod status;
pub mod visual;

use anyhow::{Result, anyhow};
use clock::NodeClock;
use flume_msgs::builtin_interfaces::Time;
use flume_msgs::rosgraph_msgs::Clock;
use flume_msgs::sensor_msgs::PointCloud2;
use flume_msgs::std_msgs::Header;
use flume_solver::Observations;
use gate::{InputGate, Limits};
use messages::Outputs;
use pacer::Pacer;
use readings::{Readings, compared_at};
use samples::{Admitted, Input, Sample};
use settings::Settings;
use solver_thread::{Command, Report, SolverLink};
use status::{Counters, Period};
use std::time::Instant;

/// The case's gauges by name, in the case's order: the twin's sensors besides the inflow.
pub fn gauge_names(case: &flume_solver::Case) -> Vec<String> {
    case.observations
        .gauges
        .iter()
        .map(|g| g.name.clone())
        .collect()
}

/// How close to `--until` the twin counts as there: 1 us, less than any step. Driven by
/// sensors, a chunk ends at the newest sample's stamp (ns since the epoch, less the origin),
/// which can leave the twin a fraction of a microsecond short; a chunk for that fraction would
/// publish its outputs a second time at what reads as the same stamp.
const UNTIL_TOLERANCE_S: f64 = 1e-6;

/// What a live twin keeps for the whole run (the settings that may change live are apart).
#[derive(Debug, Clone)]
pub struct Options {
    /// The case's gauges, by name, in the case's order.
    pub gauge_names: Vec<String>,
    /// The node's name, as /diagnostics names the twin: fully qualified, since every twin on
    /// the network reports on the one /diagnostics topic.
    pub node_name: String,
    /// Hold at t = 0 until the first sensor sample.
    pub wait_for_sensors: bool,
    /// The longest chunk the solver runs before it reports, s.
    pub max_chunk_s: f64,
    /// Stop at this simulated time, s.
    pub until: Option<f64>,
    /// How often the point cloud is read back, Hz, and its largest size.
    pub cloud_rate_hz: f64,
    pub cloud_max_points: usize,
}

/// The twin's services (std_srvs/Trigger), under the node's name.
#[derive(Debug, Clone, Copy)]
pub enum Service {
    Reset,
    Pause,
    Resume,
    Step,
}

impl Service {
    pub const ALL: [Service; 4] = [
        Service::Reset,
        Service::Pause,
        Service::Resume,
        Service::Step,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Service::Reset => "reset",
            Service::Pause => "pause",
            Service::Resume => "resume",
            Service::Step => "step",
        }
    }
}

/// What goes out after a solver report.
pub struct Published {
    pub clock: Clock,
    pub cloud: Option<PointCloud2>,
    /// None when decimated to the publish rate.
    pub outputs: Option<Outputs>,
    /// The twin reached `--until`.
    pub last: bool,
}

pub struct Twin {
    options: Options,
    limits: Limits,
    settings: Settings,
    gate: InputGate,
    pacer: Pacer,
    readings: Vec<Readings>,
    clock: NodeClock,
    solver: SolverLink,
    /// Commands sent to the solver and not yet reported.
    outstanding: u32,
    /// A reset the twin asked for itself (the clock went back) has already renewed the inputs.
    reset_by_clock: bool,
    paused: bool,
    sim_t: f64,
    last_obs: Observations,
    last_publish: Option<Instant>,
    last_cloud: Option<Instant>,
    counters: Counters,
    period: Period,
    /// The terminal's line gives the factor over its own ten seconds: over one, a twin that
    /// advances in 0.1 s chunks reads 0 or 0.1.
    line_period: Period,
    status_count: u64,
}

impl Twin {
    pub fn new(options: Options, limits: Limits, settings: Settings, solver: SolverLink) -> Twin {
        let readings = vec![Readings::default(); options.gauge_names.len()];
        Twin {
            gate: InputGate::new(limits.clone()),
            pacer: Pacer::new(
                settings.target_rtf,
                settings.stale_after_s,
                options.wait_for_sensors,
            ),
            clock: NodeClock::new(settings.use_sim_time),
            last_obs: solver.first.clone(),
            readings,
            options,
            limits,
            settings,
            solver,
            outstanding: 0,
            reset_by_clock: false,
            paused: false,
            sim_t: 0.0,
            last_publish: None,
            last_cloud: None,
            counters: Counters::default(),
            period: Period::new(0.0),
            line_period: Period::new(0.0),
            status_count: 0,
        }
    }

    /// Simulated time the solver has reached, s.
    pub fn sim_t(&self) -> f64 {
        self.sim_t
    }

    /// The settings as they were at the last tick.
    pub fn settings(&self) -> &Settings {
        &self.settings
    }

    fn send(&mut self, command: Command) -> Result<()> {
        self.solver
            .commands
            .send(command)
            .map_err(|_| anyhow!("the solver thread has stopped"))?;
        self.outstanding += 1;
        Ok(())
    }

    /// A new session's inputs: t = 0 is the next event, and what was queued or read belonged
    /// to the old one.
    fn renew_inputs(&mut self) {
        self.pacer = Pacer::new(
            self.pacer.target_rtf,
            self.pacer.stale_after_s,
            self.options.wait_for_sensors,
        );
        self.readings = vec![Readings::default(); self.options.gauge_names.len()];
    }

    /// A `/clock` message at `t` s. A player that restarted or looped starts a new session, as
    /// ROS nodes clear their buffers on a jump back: the old stamps would refuse the new.
    pub fn clock(&mut self, t: f64) -> Result<()> {
        if self.clock.set(t) {
            println!("/clock went back: the twin resets for a new session");
            self.send(Command::Reset)?;
            self.reset_by_clock = true;
            self.gate = InputGate::new(self.limits.clone());
            self.renew_inputs();
        }
        Ok(())
    }

    /// A sensor sample from `topic`, judged on the node's clock.
    pub fn sample(&mut self, topic: &str, sample: &Sample) {
        match self.clock.now() {
            Some(now) => self.sample_at(sample.input(), now),
            None => {
                // Nothing can judge its stamp before simulated time starts.
                self.counters.before_clock += 1;
                if self.counters.before_clock == 1 {
                    log::warn!(
                        "{topic}: a sample came before the first /clock message (use_sim_time): refused, as are any more until /clock starts (counted in /diagnostics)"
                    );
                }
            }
        }
    }

    /// Gates a sensor sample at node-clock time `now`; what passes goes to the pacer and to
    /// the gauge's readings.
    pub fn sample_at(&mut self, input: Input, now: f64) {
        let heights = &self.settings.mount_height_m;
        match input.admit(&mut self.gate, &self.options.gauge_names, heights, now) {
            Some(Admitted::Inflow { stamp_s, q }) => self.pacer.inflow(stamp_s, q),
            Some(Admitted::Level {
                index,
                stamp_s,
                level_m,
            }) => {
                self.pacer.heard(stamp_s);
                self.readings[index].push(stamp_s, level_m);
            }
            None => {}
        }
    }

    /// A sample from `topic` that could not be read.
    pub fn undecodable(&mut self, topic: &str, why: &str) {
        self.counters.undecodable += 1;
        log::warn!("{topic}: a sample could not be read: {why}");
    }

    /// The node's tick with the settings as they are now: when the solver is idle and the
    /// twin behind, the next chunk goes to the solver.
    pub fn tick(&mut self, live: Settings) -> Result<()> {
        if live.target_rtf != self.pacer.target_rtf {
            self.pacer.set_target_rtf(live.target_rtf);
        }
        self.pacer.stale_after_s = live.stale_after_s;
        self.settings = live;
        // Simulated time that has not started holds the twin.
        let (0, false, Some(now)) = (self.outstanding, self.paused, self.clock.now()) else {
            return Ok(());
        };
        let mut cap = self.options.max_chunk_s;
        if let Some(u) = self.options.until {
            cap = cap.min(u - self.sim_t);
        }
        let Some(chunk) = self
            .pacer
            .next_chunk(self.sim_t, now, cap)
            .filter(|_| cap > UNTIL_TOLERANCE_S)
        else {
            return Ok(());
        };
        let cloud = self
            .last_cloud
            .is_none_or(|t| t.elapsed().as_secs_f64() >= 1.0 / self.options.cloud_rate_hz);
        if cloud {
            self.last_cloud = Some(Instant::now());
        }
        self.send(Command::Advance {
            to_s: chunk.to_s,
            inflow: chunk.inflow,
            cloud,
        })
    }

    /// A solver report; what goes out, or None while simulated time has not started (there
    /// is no time to stamp outputs with).
    pub fn report(&mut self, report: Report) -> Option<Published> {
        self.take(&report);
        let Some(origin) = self.pacer.origin().or(self.clock.now()) else {
            self.last_obs = report.obs;
            return None;
        };
        let t = origin + self.sim_t;
        let header = self.header(t);
        let cloud = report.cloud.as_ref().map(|points| {
            visual::point_cloud(header.clone(), points, self.options.cloud_max_points)
        });
        // Outputs are decimated to the publish rate when the solver reports faster; inputs
        // never are.
        let due = self
            .last_publish
            .is_none_or(|t| t.elapsed().as_secs_f64() >= 1.0 / self.settings.publish_rate_hz);
        let last = self
            .options
            .until
            .is_some_and(|u| self.sim_t >= u - UNTIL_TOLERANCE_S);
        let outputs = if due || last {
            self.last_publish = Some(Instant::now());
            self.counters.published_outputs += 1;
            let now = self.clock.now();
            Some(self.outputs(&report.obs, header.clone(), t, now))
        } else {
            self.counters.decimated_outputs += 1;
            None
        };
        self.last_obs = report.obs;
        Some(Published {
            clock: Clock {
                clock: header.stamp,
            },
            cloud,
            outputs,
            last,
        })
    }

    /// What every report changes: the time reached, the inputs after a reset, the counters.
    fn take(&mut self, report: &Report) {
        self.outstanding = self.outstanding.saturating_sub(1);
        self.sim_t = report.obs.time_s;
        if report.reset {
            if !std::mem::take(&mut self.reset_by_clock) {
                self.renew_inputs();
            }
            println!("reset to the case's initial state");
        }
        self.counters.solver_refused += report.refused_inflows;
        self.counters.frames_sent = report.frames_sent;
        self.counters.frames_skipped = report.frames_skipped;
        self.period.add(report);
    }

    fn header(&self, t: f64) -> Header {
        Header {
            stamp: Time::from_secs_f64(t).unwrap_or_default(),
            frame_id: self.settings.frame_id.clone(),
        }
    }

    /// The outputs of `obs` at time `t` on the node's clock, each gauge against its reading
    /// at `t` and judged stale at `now`.
    fn outputs(&mut self, obs: &Observations, header: Header, t: f64, now: Option<f64>) -> Outputs {
        let after_s = self.settings.stale_after_s;
        let (at, stale) = compared_at(&mut self.readings, t, now, after_s);
        Outputs::of(obs, header, &at, &stale)
    }

    /// Lock-step (a replay): simulated time 0 is `origin` on the recording's clock.
    pub fn start_at(&mut self, origin: f64) {
        self.pacer.start_at(origin);
    }

    /// Lock-step: the discharge in force when the replay starts, from t = 0.
    pub fn hold_inflow(&mut self, q: f64) {
        self.pacer.hold(q);
    }

    /// Lock-step: the solver runs to `to_s` whatever the clock says, with the discharges
    /// stamped on the way.
    pub fn advance_to(&mut self, to_s: f64) -> Result<()> {
        let chunk = self.pacer.chunk_to(self.sim_t, to_s);
        self.send(Command::Advance {
            to_s,
            inflow: chunk.inflow,
            cloud: false,
        })
    }

    /// Lock-step: the outputs of the observations at hand (the case's initial state, before
    /// any report) at `t` on the recording's clock.
    pub fn outputs_now(&mut self, t: f64) -> Outputs {
        let obs = self.last_obs.clone();
        self.outputs(&obs, self.header(t), t, Some(t))
    }

    /// Lock-step: a solver report and all its outputs (none decimated) at `t` on the
    /// recording's clock, a gauge stale when its last sample is older than `t` by more than
    /// the settings allow.
    pub fn report_at(&mut self, report: Report, t: f64) -> Outputs {
        self.take(&report);
        let out = self.outputs(&report.obs, self.header(t), t, Some(t));
        self.last_obs = report.obs;
        out
    }

    /// The samples the gate refused, by reason.
    pub fn refused(&self) -> &std::collections::BTreeMap<&'static str, u64> {
        self.gate.refused()
    }

    /// A service call: whether it was done, and what to answer.
    pub fn service(&mut self, which: Service) -> Result<(bool, String)> {
        let sim_t = self.sim_t;
        Ok(match which {
            Service::Pause => {
                self.paused = true;
                (
                    true,
                    format!("paused at t = {sim_t:.3} s; inputs are still taken"),
                )
            }
            Service::Resume => {
                self.paused = false;
                self.pacer.set_target_rtf(self.pacer.target_rtf);
                (true, format!("resumed at t = {sim_t:.3} s"))
            }
            Service::Step if !self.paused => (false, "pause the twin first".to_string()),
            Service::Step if self.clock.now().is_none() => (
                false,
                "simulated time has not started: no /clock yet".to_string(),
            ),
            Service::Step => {
                let chunk = self.pacer.step(sim_t, self.options.max_chunk_s);
                let to = chunk.to_s;
                self.send(Command::Advance {
                    to_s: to,
                    inflow: chunk.inflow,
                    cloud: true,
                })?;
                (true, format!("stepping from t = {sim_t:.3} s to {to:.3} s"))
            }
            Service::Reset => {
                self.send(Command::Reset)?;
                (true, "resetting to the case's initial state".to_string())
            }
        })
    }
}
