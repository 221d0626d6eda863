//! `flume-twin replay REC.mcap --config CASE --out OUT.mcap`: a recorded session's sensor
//! topics fed to the twin in-process, no DDS. Simulated time 0 is the first replayed sample's
//! stamp; the solver runs in lock-step chunks ending on a fixed grid of `--output-interval-s`,
//! each discharge applied at its own stamp, so the same recording on the same adapter gives
//! the same bits out. The output recording holds the replayed inputs (as recorded) and the
//! twin's outputs, stamped on the recording's clock. With `--publish` the sensor topics go on
//! the wire instead (`play`).

use crate::adapters::bag::writer::Channel as BagChannel;
use crate::adapters::bag::{BagFile, BagMessage, BagWriter};
use crate::adapters::ros::args::RosArgs;
use crate::adapters::topics;
use crate::cli::ReplayArgs;
use crate::twin::gate::{InputGate, Limits};
use crate::twin::messages::Outputs;
use crate::twin::readings::{Readings, compared_at};
use crate::twin::samples::{Admitted, Input, decode, role};
use crate::twin::settings::mount_heights;
use crate::twin::solver_thread::{self, Command};
use anyhow::{Context, Result, anyhow, bail};
use flume_msgs::RosMessage;
use flume_msgs::builtin_interfaces::Time;
use flume_msgs::flume_msgs::{BedProfile, Discharge, ErodedMass, GaugeComparison};
use flume_msgs::rosgraph_msgs::Clock;
use flume_msgs::std_msgs::Header;
use flume_msgs::visualization_msgs::MarkerArray;
use flume_solver::Case;
use std::collections::BTreeMap;
use std::time::{Duration, Instant};

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

    /// The twin's outputs for `obs`, stamped `stamp`, the gauges compared with `measured`.
    fn observation(
        &mut self,
        obs: &flume_solver::Observations,
        stamp: Time,
        measured: &[Option<f64>],
        stale: &[bool],
    ) -> Result<()> {
        let ns = stamp.as_nanos().unwrap_or(0);
        let header = Header {
            stamp,
            frame_id: "flume".into(),
        };
        let out = Outputs::of(obs, header, measured, stale);
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
    let recording = BagFile::read(&args.recording)?;
    if let Some(damage) = &recording.damage {
        log::warn!("{damage}; replaying what comes before it");
        eprintln!("warning: {damage}; replaying what comes before it");
    }
    let gauge_names: Vec<String> = case
        .observations
        .gauges
        .iter()
        .map(|g| g.name.clone())
        .collect();
    let selected = |topic: &str| args.topics.is_empty() || args.topics.iter().any(|t| t == topic);
    // (message, role) in log order; what the twin does not take is said once per topic.
    let mut feed: Vec<(&BagMessage, Option<usize>)> = Vec::new();
    let mut ignored: BTreeMap<&str, (&str, u64)> = BTreeMap::new();
    for m in &recording.messages {
        match role(m, &gauge_names).filter(|_| selected(&m.topic)) {
            Some(r) => feed.push((m, r)),
            None => ignored.entry(&m.topic).or_insert((&m.schema_name, 0)).1 += 1,
        }
    }
    for (topic, (schema, n)) in &ignored {
        println!("not replayed: {topic} ({schema}, {n} messages)");
    }
    feed.sort_by_key(|(m, _)| m.log_ns);
    let Some(first_ns) = feed.first().map(|(m, _)| m.log_ns) else {
        bail!(
            "{} holds no inflow or gauge topic of this case ({}) to replay",
            args.recording.display(),
            gauge_names.join(", ")
        );
    };
    let start_ns = first_ns + crate::adapters::bag::writer::nanos(args.start_s);
    let limits = Limits::for_case(&case, args.future_tolerance_s);
    let mut gate = InputGate::new(limits.clone());
    let mut undecodable = 0u64;
    // Samples before the start are passed over, but the discharge in force at the start holds.
    let mut events: Vec<(usize, Input)> = Vec::new();
    let mut carried: Option<(usize, f64)> = None;
    for (k, (m, r)) in feed.iter().enumerate() {
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
                carried = Some((k, q));
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
    let mut inflow: Vec<(f64, f64)> = carried.map(|(_, q)| (0.0, q)).into_iter().collect();
    let mut measured: Vec<Readings> = vec![Readings::default(); gauge_names.len()];
    let mut fed: Vec<usize> = Vec::new();
    let mount_height_m = mount_heights(&ros, &gauge_names, limits.flume_height_m)?;
    for &(k, input) in &events {
        let now = feed[k].0.log_ns as f64 * 1e-9;
        fed.push(k);
        match input.admit(&mut gate, &gauge_names, &mount_height_m, now) {
            Some(Admitted::Inflow { stamp_s, q }) => inflow.push((stamp_s - origin, q)),
            Some(Admitted::Level {
                index,
                stamp_s,
                level_m,
            }) => measured[index].push(stamp_s, level_m),
            None => {}
        }
    }
    println!(
        "replaying {} samples of {} up to {end:.3} s of simulated time",
        events.len(),
        args.recording.display(),
    );

    let solver_thread::SolverThread {
        link:
            solver_thread::SolverLink {
                commands,
                adapter,
                particles,
                first,
            },
        mut reports,
        handle,
    } = solver_thread::spawn(case, args.csv.clone(), None)?;
    println!("adapter: {adapter}\nparticles: {particles}");
    let mut out = args.out.as_deref().map(OutputBag::create).transpose()?;
    // A gauge is stale when its last sample is older than the output by more than
    // `--stale-after-s` (a live twin judges by its clock instead).
    let compare_at =
        |measured: &mut [Readings], t: f64| compared_at(measured, t, Some(t), args.stale_after_s);
    if let Some(out) = out.as_mut() {
        let (at, stale) = compare_at(&mut measured, origin);
        out.observation(
            &first,
            Time::from_secs_f64(origin).unwrap_or_default(),
            &at,
            &stale,
        )?;
    }
    let started = Instant::now();
    let mut next_input = 0usize;
    let mut next_inflow = 0usize;
    let mut t = 0.0f64;
    let mut steps = 0u64;
    let mut chunk = 0u64;
    while t < end {
        chunk += 1;
        let to = (chunk as f64 * args.output_interval_s).min(end);
        if let Some(rate) = args.rate {
            let due = Duration::from_secs_f64(to / rate);
            if let Some(wait) = due.checked_sub(started.elapsed()) {
                std::thread::sleep(wait);
            }
        }
        let mut changes = Vec::new();
        while let Some(&(ts, q)) = inflow.get(next_inflow).filter(|(ts, _)| *ts <= to) {
            changes.push((ts.max(t), q));
            next_inflow += 1;
        }
        commands
            .send(Command::Advance {
                to_s: to,
                inflow: changes,
                cloud: false,
            })
            .map_err(|_| anyhow!("the solver thread has stopped"))?;
        let report = reports
            .blocking_recv()
            .ok_or_else(|| anyhow!("the solver thread has stopped"))?
            .map_err(|e| anyhow!("the solver stopped: {e}"))?;
        steps += report.steps;
        t = report.obs.time_s;
        let Some(out) = out.as_mut() else { continue };
        while let Some(&k) = fed.get(next_input) {
            let m = feed[k].0;
            if m.log_ns as f64 * 1e-9 - origin > to {
                break;
            }
            out.input(m)?;
            next_input += 1;
        }
        let (at, stale) = compare_at(&mut measured, origin + to);
        let stamp = Time::from_secs_f64(origin + to).unwrap_or_default();
        out.observation(&report.obs, stamp, &at, &stale)?;
    }
    drop(commands);
    if handle.join().is_err() {
        log::warn!("the solver thread panicked");
    }
    let wall = started.elapsed().as_secs_f64();
    if let Some(mut out) = out {
        for &k in &fed[next_input..] {
            out.input(feed[k].0)?;
        }
        let path = out.bag.path().to_path_buf();
        out.bag.finish()?;
        println!("wrote {}", path.display());
    }
    let refused: Vec<String> = gate
        .refused()
        .iter()
        .map(|(k, n)| format!("{k} {n}"))
        .collect();
    println!(
        "replayed {t:.3} s in {wall:.1} s ({:.3} simulated s per wall s), {steps} steps, {chunk} chunks; \
         refused inputs: {}; undecodable: {undecodable}",
        t / wall.max(1e-9),
        if refused.is_empty() {
            "none".to_string()
        } else {
            refused.join(", ")
        }
    );
    Ok(())
}
