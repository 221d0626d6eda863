//! `flume-twin replay REC --config CASE --out OUT`: a recorded session's sensor
//! topics fed to the twin in-process, no DDS. Simulated time 0 is the first replayed sample's
//! stamp; the solver runs in lock-step chunks ending on a fixed grid of `--output-interval-s`,
//! each discharge applied at its own stamp, so the same recording on the same adapter gives
//! the same bits out. The output recording holds the replayed inputs (as recorded) and the
//! twin's outputs, stamped on the recording's clock. The live node's [`Twin`] gates the
//! samples, applies each discharge at its stamp and makes the outputs; only the pace is this
//! module's. With `--publish` the sensor topics go on the wire instead (`play`).

use crate::adapters::bag::samples::{decode, role};
use crate::adapters::bag::writer::Channel as BagChannel;
use crate::adapters::bag::{BagFile, BagMessage, BagWriter};
use crate::adapters::files::outputs::recorder_in;
use crate::adapters::files::series_plot::SeriesPlots;
use crate::adapters::ros::args::RosArgs;
use crate::adapters::topics;
use crate::cli::ReplayArgs;
use crate::twin::gate::Limits;
use crate::twin::messages::Outputs;
use crate::twin::samples::Input;
use crate::twin::settings::{Settings, mount_heights};
use crate::twin::solver_thread::{self, ChunkSinks, Report, SolverLink};
use crate::twin::{Options, Twin, gauge_names};
use anyhow::{Context, Result, anyhow, bail};
use flume_msgs::RosMessage;
use flume_msgs::builtin_interfaces::Time;
use flume_msgs::flume_msgs::{BedProfile, Discharge, ErodedMass, GaugeComparison};
use flume_msgs::rosgraph_msgs::Clock;
use flume_msgs::visualization_msgs::MarkerArray;
use flume_solver::Case;
use std::collections::BTreeMap;
use std::time::{Duration, Instant};
use tokio::sync::mpsc;

/// The output recording's channels.
struct OutputBag {
    bag: BagWriter,
    inputs: BTreeMap<String, BagChannel>,
    clock: BagChannel,
    bed: BagChannel,
    eroded: BagChannel,
    compare: BagChannel,
    marker: BagChannel,
}

impl OutputBag {
    /// Writes the feed's inputs from `written` on (those the run did not reach) and closes
    /// the bag.
    fn finish_with(mut self, feed: &Feed, written: usize) -> Result<()> {
        for &(k, _) in &feed.events[written..] {
            self.input(feed.messages[k].0)?;
        }
        let path = self.bag.path().to_path_buf();
        self.bag.finish()?;
        println!("wrote {}", path.display());
        Ok(())
    }

    fn create(path: &std::path::Path) -> Result<OutputBag> {
        let mut bag = BagWriter::create(path, None)?;
        let abs = |t: &str| format!("/{}", t.trim_start_matches('/'));
        Ok(OutputBag {
            inputs: BTreeMap::new(),
            clock: bag.channel::<Clock>(&abs(topics::CLOCK), topics::STREAM_QOS)?,
            bed: bag.channel::<BedProfile>(&abs(topics::BED_PROFILE), topics::LATCHED_QOS)?,
            eroded: bag.channel::<ErodedMass>(&abs(topics::ERODED_MASS), topics::OUTPUT_QOS)?,
            compare: bag
                .channel::<GaugeComparison>(&abs(topics::GAUGE_COMPARISON), topics::OUTPUT_QOS)?,
            marker: bag.channel::<MarkerArray>(&abs(topics::BED_MARKER), topics::LATCHED_QOS)?,
            bag,
        })
    }

    /// The twin's outputs, stamped `stamp`.
    fn observation(&mut self, out: &Outputs, stamp: Time) -> Result<()> {
        let ns = stamp.as_nanos().unwrap_or(0);
        self.bag
            .write(self.clock, &Clock { clock: stamp }, ns, ns)?;
        self.bag.write(self.marker, &out.marker, ns, ns)?;
        self.bag.write(self.bed, &out.bed, ns, ns)?;
        if let Some(msg) = &out.eroded {
            self.bag.write(self.eroded, msg, ns, ns)?;
        }
        self.bag.write(self.compare, &out.comparison, ns, ns)
    }

    /// Copies a replayed input as it was recorded.
    fn input(&mut self, msg: &BagMessage) -> Result<()> {
        let channel = match self.inputs.get(&msg.topic) {
            Some(c) => *c,
            None => {
                let qos = msg.offered_qos_profiles.clone().unwrap_or_else(|| {
                    if msg.schema_name == Discharge::DEF.schema_name() {
                        topics::INFLOW_QOS
                    } else {
                        topics::GAUGE_QOS
                    }
                    .offered_qos_profiles()
                });
                let c =
                    self.bag
                        .raw_channel(&msg.topic, &msg.schema_name, &msg.definition, &qos)?;
                self.inputs.insert(msg.topic.clone(), c);
                c
            }
        };
        self.bag
            .write_raw(channel, &msg.data, msg.log_ns, msg.publish_ns)
    }
}

/// Replays `args.recording` through the twin.
pub fn run(args: &ReplayArgs, ros_args: &[String]) -> Result<()> {
    let ros = RosArgs::parse(ros_args).context("bad --ros-args")?;
    if !ros.remaps.is_empty() {
        log::warn!(
            "an in-process replay matches topics by their last segments: remaps are ignored"
        );
    }
    let case = replayed_case(args)?;
    let recording = BagFile::read(&args.recording)?;
    if let Some(damage) = &recording.damage {
        log::warn!("{damage}; replaying what comes before it");
        eprintln!("warning: {damage}; replaying what comes before it");
    }
    let gauge_names = gauge_names(&case);
    let feed = Feed::read(args, &recording, &gauge_names)?;
    let limits = Limits::for_case(&case, args.future_tolerance_s);
    let params = ros.parameters(&ros.node_fqn("flume_twin"))?;
    let mount_height_m = mount_heights(&params, &gauge_names, limits.flume_height_m)?;
    println!(
        "replaying {} samples of {} up to {:.3} s of simulated time",
        feed.events.len(),
        args.recording.display(),
        feed.end
    );
    let case_name = case.name.clone();
    let chunk_sinks = ChunkSinks {
        recorder: args.csv.clone().map(recorder_in),
        frames: None,
    };
    let solver = solver_thread::spawn(case, chunk_sinks)?;
    println!(
        "adapter: {}\nparticles: {}",
        solver.link.adapter, solver.link.particles
    );
    let settings = Settings::for_replay(&gauge_names, mount_height_m, args.stale_after_s);
    let mut twin = fed_twin(args, &feed, gauge_names, (limits, settings), solver.link);
    let mut out = args.out.as_deref().map(OutputBag::create).transpose()?;
    // The plots go beside the CSV files they draw.
    let mut plots = args.csv.as_ref().map(|_| SeriesPlots::compared());
    let mut reports = solver.reports;
    let started = Instant::now();
    let sinks = Sinks {
        bag: out.as_mut(),
        plots: plots.as_mut(),
    };
    let ran = lock_step(args, &mut twin, &feed, &mut reports, sinks)?;
    let refused = refused_inputs(twin.refused());
    // Closing the solver's channel stops it.
    drop(twin);
    if solver.handle.join().is_err() {
        log::warn!("the solver thread panicked");
    }
    let wall = started.elapsed().as_secs_f64();
    if let Some(out) = out {
        out.finish_with(&feed, ran.inputs_written)?;
    }
    if let (Some(plots), Some(dir)) = (&plots, &args.csv) {
        for path in plots.draw(dir, &case_name)? {
            println!("plot: {}", path.display());
        }
    }
    let t = ran.t;
    println!(
        "replayed {t:.3} s in {wall:.1} s ({:.3} simulated s per wall s), {} steps, {} chunks; \
         refused inputs: {}; undecodable: {}",
        t / wall.max(1e-9),
        ran.steps,
        ran.chunks,
        refused,
        feed.undecodable
    );
    Ok(())
}

/// The inputs the twin refused, by reason: "none", or "reason count, ...".
fn refused_inputs(refused: &std::collections::BTreeMap<&'static str, u64>) -> String {
    if refused.is_empty() {
        return "none".to_string();
    }
    let each: Vec<String> = refused.iter().map(|(k, n)| format!("{k} {n}")).collect();
    each.join(", ")
}

/// The case `--config` names with its `--set`s, which must have an open flume.
fn replayed_case(args: &ReplayArgs) -> Result<Case> {
    let Some(config) = &args.config else {
        bail!("--config CASE is needed to replay through the twin");
    };
    let case = Case::from_path_with(config, &args.set).context("the case file was refused")?;
    if case.open_flume.is_none() {
        bail!(
            "{}: the twin needs an open flume for the recorded inflow to drive",
            config.display()
        );
    }
    Ok(case)
}

/// A twin on the solver `link`, started at the feed's origin and given every sample at its
/// log time, as a live twin would have judged it.
fn fed_twin(
    args: &ReplayArgs,
    feed: &Feed,
    gauge_names: Vec<String>,
    (limits, settings): (Limits, Settings),
    link: SolverLink,
) -> Twin {
    let options = Options {
        gauge_names,
        node_name: "flume_twin".into(),
        wait_for_sensors: true,
        max_chunk_s: args.output_interval_s,
        until: None,
        cloud_rate_hz: 0.0,
        cloud_max_points: 0,
    };
    let mut twin = Twin::new(options, limits, settings, link);
    twin.start_at(feed.origin);
    if let Some(q) = feed.carried {
        twin.hold_inflow(q);
    }
    for &(k, input) in &feed.events {
        twin.sample_at(input, feed.messages[k].0.log_ns as f64 * 1e-9);
    }
    twin
}

/// A recording's sensor samples as a replay takes them.
struct Feed<'a> {
    /// (message, role) of each sample of the case's topics, in log order.
    messages: Vec<(&'a BagMessage, Option<usize>)>,
    /// The samples replayed, from `--start-s` to the end: index in `messages`, and the input.
    events: Vec<(usize, Input)>,
    /// The discharge in force at the start: samples before it are passed over, it holds.
    carried: Option<f64>,
    /// The first replayed sample's stamp: simulated time 0, s.
    origin: f64,
    /// Simulated time the replay ends at, s.
    end: f64,
    undecodable: u64,
}

impl<'a> Feed<'a> {
    fn read(args: &ReplayArgs, recording: &'a BagFile, gauge_names: &[String]) -> Result<Feed<'a>> {
        let selected =
            |topic: &str| args.topics.is_empty() || args.topics.iter().any(|t| t == topic);
        // What the twin does not take is said once per topic.
        let mut messages: Vec<(&BagMessage, Option<usize>)> = Vec::new();
        let mut ignored: BTreeMap<&str, (&str, u64)> = BTreeMap::new();
        for m in &recording.messages {
            match role(m, gauge_names).filter(|_| selected(&m.topic)) {
                Some(r) => messages.push((m, r)),
                None => ignored.entry(&m.topic).or_insert((&m.schema_name, 0)).1 += 1,
            }
        }
        for (topic, (schema, n)) in &ignored {
            println!("not replayed: {topic} ({schema}, {n} messages)");
        }
        messages.sort_by_key(|(m, _)| m.log_ns);
        let Some(first_ns) = messages.first().map(|(m, _)| m.log_ns) else {
            bail!(
                "{} holds no inflow or gauge topic of this case ({}) to replay",
                args.recording.display(),
                gauge_names.join(", ")
            );
        };
        let start_ns = first_ns + crate::adapters::bag::writer::nanos(args.start_s);
        let mut undecodable = 0u64;
        let mut events: Vec<(usize, Input)> = Vec::new();
        let mut carried = None;
        for (k, (m, r)) in messages.iter().enumerate() {
            let input = match decode(m, *r) {
                Ok(sample) => sample.input(),
                Err(e) => {
                    undecodable += 1;
                    log::warn!("{e:#}");
                    continue;
                }
            };
            if m.log_ns < start_ns {
                if let Input::Inflow { q, .. } = input {
                    carried = Some(q);
                }
                continue;
            }
            events.push((k, input));
        }
        let origin = if let Some(&(_, first)) = events.first() {
            first.stamp_s()
        } else {
            bail!("nothing to replay after --start-s {} s", args.start_s);
        };
        let last = events.last().map_or(0.0, |(_, i)| i.stamp_s() - origin);
        let end = args.until.map_or(last, |u| u.min(last));
        events.retain(|(_, i)| i.stamp_s() - origin <= end);
        Ok(Feed {
            messages,
            events,
            carried,
            origin,
            end,
            undecodable,
        })
    }
}

/// How far a lock-step replay went.
struct Ran {
    t: f64,
    steps: u64,
    chunks: u64,
    /// The replayed inputs already copied to the output recording.
    inputs_written: usize,
}

/// Where a replay's outputs go besides the CSV files: the output recording, the plots.
struct Sinks<'a> {
    bag: Option<&'a mut OutputBag>,
    plots: Option<&'a mut SeriesPlots>,
}

/// Runs the twin in chunks ending on the grid of `--output-interval-s` (paced by `--rate`
/// when given), writing the inputs of each chunk and the twin's outputs at its end.
fn lock_step(
    args: &ReplayArgs,
    twin: &mut Twin,
    feed: &Feed,
    reports: &mut mpsc::UnboundedReceiver<Result<Report, String>>,
    sinks: Sinks,
) -> Result<Ran> {
    let Sinks {
        bag: mut out,
        mut plots,
    } = sinks;
    if out.is_some() || plots.is_some() {
        let outputs = twin.outputs_now(feed.origin);
        if let Some(plots) = plots.as_mut() {
            plots.compare(0.0, &outputs.comparison, outputs.eroded.as_ref());
        }
        if let Some(out) = out.as_mut() {
            let stamp = Time::from_secs_f64(feed.origin).unwrap_or_default();
            out.observation(&outputs, stamp)?;
        }
    }
    let started = Instant::now();
    let mut ran = Ran {
        t: 0.0,
        steps: 0,
        chunks: 0,
        inputs_written: 0,
    };
    while ran.t < feed.end {
        ran.chunks += 1;
        let to = (ran.chunks as f64 * args.output_interval_s).min(feed.end);
        if let Some(rate) = args.rate {
            let due = Duration::from_secs_f64(to / rate);
            if let Some(wait) = due.checked_sub(started.elapsed()) {
                std::thread::sleep(wait);
            }
        }
        twin.advance_to(to)?;
        let report = reports
            .blocking_recv()
            .ok_or_else(|| anyhow!("the solver thread has stopped"))?
            .map_err(|e| anyhow!("the solver stopped: {e}"))?;
        ran.steps += report.steps;
        let outputs = twin.report_at(report, feed.origin + to);
        ran.t = twin.sim_t();
        if let Some(plots) = plots.as_mut() {
            plots.compare(to, &outputs.comparison, outputs.eroded.as_ref());
        }
        let Some(out) = out.as_mut() else { continue };
        while let Some(&(k, _)) = feed.events.get(ran.inputs_written) {
            let m = feed.messages[k].0;
            if m.log_ns as f64 * 1e-9 - feed.origin > to {
                break;
            }
            out.input(m)?;
            ran.inputs_written += 1;
        }
        let stamp = Time::from_secs_f64(feed.origin + to).unwrap_or_default();
        out.observation(&outputs, stamp)?;
    }
    Ok(ran)
}
