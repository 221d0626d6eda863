//! `flume-twin run CASE [--ros-args ...]`: the twin as a ROS 2 node (ros2-client on tokio).
//!
//! Sensor samples come in on `inflow` and `gauges/<name>`, pass the input gate, and set how
//! far the pacer lets the solver run; the solver runs on its own thread; its observations go
//! out as the bed profile, the eroded mass, the gauge comparison, `/clock` and, once a
//! second, `/diagnostics`. This module knows topics and times, not SPH.

use crate::adapters::bag::BagFile;
use crate::adapters::bag::tap::{Tap, input_channels};
use crate::adapters::ros::args::RosArgs;
use crate::adapters::ros::{dds_context, full_topic, live_parameters, outlet, qos, subscription};
use crate::adapters::topics;
use crate::cli::{GaugeMsg, RunArgs};
use crate::twin::clock::NodeClock;
use crate::twin::gate::{InputGate, Limits, Readings};
use crate::twin::messages::{bed_profile, comparison, eroded_mass};
use crate::twin::pacer::Pacer;
use crate::twin::samples::{Admitted, Input, Sample, decode, role};
use crate::twin::settings::Settings;
use crate::twin::solver_thread::{self, Command, Report};
use crate::twin::visual;
use anyhow::{Context as _, Result, anyhow, bail};
use flume_msgs::builtin_interfaces::Time;
use flume_msgs::diagnostic_msgs::{DiagnosticArray, DiagnosticStatus, KeyValue};
use flume_msgs::flume_msgs::{BedProfile, Discharge, ErodedMass, GaugeComparison, WaterLevel};
use flume_msgs::rosgraph_msgs::Clock;
use flume_msgs::sensor_msgs::{PointCloud2, Range};
use flume_msgs::std_msgs::Header;
use flume_msgs::std_srvs::{TriggerRequest, TriggerResponse};
use flume_msgs::visualization_msgs::MarkerArray;
use flume_solver::{Case, Observations};
use futures::StreamExt;
use ros2_client::{Name, NodeName, NodeOptions, ParameterValue, ServiceMapping, ServiceTypeName};
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// Runs the node until Ctrl-C (or `--until`).
pub fn run(args: &RunArgs, ros_args: &[String]) -> Result<()> {
    let case = Case::from_path_with(&args.case, &args.set).context("the case file was refused")?;
    if case.open_flume.is_none() {
        bail!(
            "{}: the twin needs an open flume (open_flume: in the case) for its inflow to drive",
            args.case.display()
        );
    };
    let ros = RosArgs::parse(ros_args).context("bad --ros-args")?;
    let namespace = ros.namespace.clone().unwrap_or_else(|| "/".into());
    let node_name = ros.node_name.clone().unwrap_or_else(|| "flume_twin".into());
    let fqn = ros.node_fqn("flume_twin");
    let vertical = case.dim() - 1;
    let gauges: Vec<String> = case
        .observations
        .gauges
        .iter()
        .map(|g| g.name.to_lowercase())
        .collect();
    let settings = Settings::new(
        args,
        &gauges,
        case.domain.max_m[vertical] - case.domain.min_m[vertical],
        &ros.parameters(&fqn)?,
    )?;
    let limits = Limits::for_case(&case, args.future_tolerance_s);
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .enable_all()
        .build()
        .context("cannot start the async runtime")?;
    runtime.block_on(serve(
        args, case, ros, namespace, node_name, settings, limits,
    ))
}

#[allow(clippy::too_many_arguments)]
async fn serve(
    args: &RunArgs,
    case: Case,
    ros: RosArgs,
    namespace: String,
    node_name: String,
    settings: Settings,
    limits: Limits,
) -> Result<()> {
    let gauge_names: Vec<String> = case
        .observations
        .gauges
        .iter()
        .map(|g| g.name.clone())
        .collect();
    let solver_thread::SolverThread {
        commands,
        mut reports,
        adapter,
        particles,
        first,
        handle,
    } = solver_thread::spawn(
        case,
        args.out.clone(),
        (!args.no_frames).then(|| solver_thread::FrameSettings {
            service: args.frames_service.clone(),
            rate_hz: args.frames_rate_hz,
        }),
    )?;
    println!("adapter: {adapter}\nparticles: {particles}\nnode: {namespace} {node_name}");

    let live = Arc::new(Mutex::new(settings.clone()));
    let mut settings = settings;
    let context = dds_context(args.loopback, args.domain_id)?;
    let mut node = context
        .new_node(
            NodeName::new(&namespace, &node_name)
                .map_err(|e| anyhow!("node name {namespace} {node_name}: {e}"))?,
            live_parameters(NodeOptions::new().enable_rosout(true), &live),
        )
        .context("cannot create the ROS 2 node")?;
    let spinner = node.spinner().context("cannot spin the node")?;
    tokio::spawn(spinner.spin());

    let full = |name: &str| full_topic(&namespace, &ros, name);
    let inflow_sub =
        subscription::<Discharge>(&mut node, &full, topics::INFLOW, qos(topics::INFLOW_QOS))?;
    let mut level_subs = Vec::new();
    let mut range_subs = Vec::new();
    for g in &gauge_names {
        let topic = topics::gauge(g);
        match args.gauge_msg {
            GaugeMsg::WaterLevel => level_subs.push(subscription::<WaterLevel>(
                &mut node,
                &full,
                &topic,
                qos(topics::GAUGE_QOS),
            )?),
            GaugeMsg::Range => range_subs.push(subscription::<Range>(
                &mut node,
                &full,
                &topic,
                qos(topics::GAUGE_QOS),
            )?),
        }
    }
    // ros2-client's own simulated time listens to /clock as builtin_interfaces/Time, which a
    // player's rosgraph_msgs/Clock does not match; the node keeps its own.
    let clock_sub = if settings.use_sim_time {
        Some(subscription::<Clock>(
            &mut node,
            &full,
            topics::CLOCK,
            qos(topics::STREAM_QOS),
        )?)
    } else {
        None
    };
    let mut recorder = Tap::create(args.record.as_deref())?;
    let inputs = input_channels(
        &mut recorder,
        &full(topics::INFLOW),
        &gauge_names
            .iter()
            .map(|g| full(&topics::gauge(g)))
            .collect::<Vec<_>>(),
        args.gauge_msg == GaugeMsg::Range,
        topics::INFLOW_QOS,
        topics::GAUGE_QOS,
    )?;
    recorder.set_inputs(inputs);
    let bed_out = outlet::<BedProfile>(
        &mut node,
        &mut recorder,
        &full,
        topics::BED_PROFILE,
        topics::LATCHED_QOS,
    )?;
    let eroded_out = outlet::<ErodedMass>(
        &mut node,
        &mut recorder,
        &full,
        topics::ERODED_MASS,
        topics::OUTPUT_QOS,
    )?;
    let compare_out = outlet::<GaugeComparison>(
        &mut node,
        &mut recorder,
        &full,
        topics::GAUGE_COMPARISON,
        topics::OUTPUT_QOS,
    )?;
    // On simulated time the player owns /clock.
    let clock_out = if settings.use_sim_time {
        None
    } else {
        Some(outlet::<Clock>(
            &mut node,
            &mut recorder,
            &full,
            topics::CLOCK,
            topics::STREAM_QOS,
        )?)
    };
    let diag_out = outlet::<DiagnosticArray>(
        &mut node,
        &mut recorder,
        &full,
        topics::DIAGNOSTICS,
        topics::OUTPUT_QOS,
    )?;
    let cloud_out = outlet::<PointCloud2>(
        &mut node,
        &mut recorder,
        &full,
        topics::PARTICLES,
        topics::STREAM_QOS,
    )?;
    let marker_out = outlet::<MarkerArray>(
        &mut node,
        &mut recorder,
        &full,
        topics::BED_MARKER,
        topics::LATCHED_QOS,
    )?;
    let mut last_cloud: Option<Instant> = None;
    let node_path = format!("{}/{node_name}", namespace.trim_end_matches('/'));
    let servers = [
        Service::Reset,
        Service::Pause,
        Service::Resume,
        Service::Step,
    ]
    .iter()
    .map(|s| {
        let qos = qos(topics::OUTPUT_QOS);
        node.create_server::<TriggerRequest, TriggerResponse>(
            ServiceMapping::Enhanced,
            &Name::new(&node_path, s.name()).map_err(|e| anyhow!("service {}: {e}", s.name()))?,
            &ServiceTypeName::new("std_srvs", "Trigger"),
            qos.clone(),
            qos,
        )
        .with_context(|| format!("cannot offer the {} service", s.name()))
    })
    .collect::<Result<Vec<_>>>()?;
    let mut service_requests =
        futures::stream::select_all(servers.iter().enumerate().map(|(k, srv)| {
            let which = [
                Service::Reset,
                Service::Pause,
                Service::Resume,
                Service::Step,
            ][k];
            Box::pin(srv.receive_request_stream().map(move |r| (which, r)))
        }));

    // Every sensor topic as one stream of (topic, sample or why it could not be read).
    type SensorStream<'a> = std::pin::Pin<
        Box<dyn futures::Stream<Item = (String, Result<Sample, String>)> + Send + 'a>,
    >;
    let error = |e: ros2_client::ReadError| format!("{e:?}");
    let mut streams: Vec<SensorStream> = vec![Box::pin(inflow_sub.async_stream().map(move |r| {
        (
            "inflow".to_string(),
            r.map(|(m, _)| Sample::Inflow(m)).map_err(error),
        )
    }))];
    for (i, s) in level_subs.iter().enumerate() {
        let name = gauge_names[i].clone();
        streams.push(Box::pin(s.async_stream().map(move |r| {
            (
                name.clone(),
                r.map(|(m, _)| Sample::Level(i, m)).map_err(error),
            )
        })));
    }
    for (i, s) in range_subs.iter().enumerate() {
        let name = gauge_names[i].clone();
        streams.push(Box::pin(s.async_stream().map(move |r| {
            (
                name.clone(),
                r.map(|(m, _)| Sample::Range(i, m)).map_err(error),
            )
        })));
    }
    let mut sensor_stream = futures::stream::select_all(streams);
    let mut clock_stream: std::pin::Pin<Box<dyn futures::Stream<Item = _> + Send>> =
        match &clock_sub {
            Some(sub) => Box::pin(sub.async_stream()),
            None => Box::pin(futures::stream::pending()),
        };
    let mut clock = NodeClock::new(settings.use_sim_time);
    let mut before_clock = 0u64;
    let mut sim_time_change_said = false;
    // With no sensor on the network, a recorded session plays the sensors' part.
    let heard_sensor = Arc::new(AtomicBool::new(false));
    let (fallback_tx, mut fallback_rx) = tokio::sync::mpsc::channel::<Sample>(64);
    // On simulated time the recorded session is the player's to play, on the wire.
    let on_sim_time = settings.use_sim_time;
    if on_sim_time && !args.no_replay {
        println!("use_sim_time: no recorded session plays the sensors here");
    }
    let fallback = args
        .replay_when_silent
        .clone()
        .filter(|_| !args.no_replay && !on_sim_time)
        .filter(|path| {
            let exists = path.exists();
            if !exists {
                log::warn!(
                    "{} does not exist: with no sensors the twin runs on the clock",
                    path.display()
                );
            }
            exists
        });
    // A player's clock may start before its first sample: t = 0 is the first sample.
    let wait_for_sensors = args.wait_for_sensors || fallback.is_some() || on_sim_time;
    if let Some(path) = fallback {
        tokio::spawn(play_when_silent(
            path,
            gauge_names.clone(),
            Duration::from_secs_f64(args.silent_wait_s),
            Arc::clone(&heard_sensor),
            fallback_tx,
        ));
    }
    let mut gate = InputGate::new(limits.clone());
    // A reset the node asked for itself (the clock went back) has already renewed the pacer.
    let mut reset_by_clock = false;
    let mut pacer = Pacer::new(
        settings.target_rtf,
        settings.stale_after_s,
        wait_for_sensors,
    );
    let mut measured: Vec<Readings> = vec![Readings::default(); gauge_names.len()];
    let mut sim_t = 0.0;
    // Commands sent to the solver and not yet reported.
    let mut outstanding = 0u32;
    let mut paused = false;
    let mut undecodable = 0u64;
    let mut solver_refused = 0u64;
    let (mut frames_sent, mut frames_skipped) = (0u64, 0u64);
    let mut published_outputs = 0u64;
    let mut decimated_outputs = 0u64;
    let mut last_publish: Option<Instant> = None;
    let mut last_obs: Observations = first;
    let mut period = Period::new(sim_t);
    let mut tick = tokio::time::interval(Duration::from_millis(20));
    let mut diag_tick = tokio::time::interval(Duration::from_secs(1));
    let mut diag_count = 0u64;
    // The terminal's line gives the factor over its own ten seconds: over one, a twin that
    // advances in 0.1 s chunks reads 0 or 0.1.
    let mut status_period = Period::new(sim_t);
    let until = args.until;
    let mut shutdown = Box::pin(tokio::signal::ctrl_c());
    let mut terminate = tokio::signal::unix::signal(tokio::signal::unix::SignalKind::terminate())
        .context("cannot watch for SIGTERM")?;
    println!(
        "listening: {} and {} gauge topics",
        full(topics::INFLOW),
        gauge_names.len()
    );
    loop {
        tokio::select! {
            // In order: a player sends /clock just before a sample, on another writer, and
            // the sample is judged on that clock. Nothing here comes fast enough to starve
            // the branches after it.
            biased;
            _ = &mut shutdown => {
                println!("interrupted at t = {sim_t:.3} s");
                break;
            }
            _ = terminate.recv() => {
                println!("terminated at t = {sim_t:.3} s");
                break;
            }
            Some(r) = clock_stream.next() => match r {
                Ok((c, _)) => {
                    if clock.set(c.clock.as_secs_f64()) {
                        // A player restarted or looped: a new session, as ROS nodes clear
                        // their buffers on a jump back; the old stamps would refuse the new.
                        println!("/clock went back: the twin resets for a new session");
                        commands
                            .send(Command::Reset)
                            .map_err(|_| anyhow!("the solver thread has stopped"))?;
                        outstanding += 1;
                        reset_by_clock = true;
                        gate = InputGate::new(limits.clone());
                        pacer = Pacer::new(pacer.target_rtf, pacer.stale_after_s, wait_for_sensors);
                        measured = vec![Readings::default(); gauge_names.len()];
                    }
                }
                Err(e) => log::warn!("/clock: a message could not be read: {e:?}"),
            },
            Some((topic, r)) = sensor_stream.next() => match r {
                Ok(sample) => {
                    if !heard_sensor.swap(true, Ordering::Relaxed) {
                        println!("sensors heard on {topic}");
                    }
                    recorder.input(&sample);
                    match clock.now() {
                        Some(now) => take(sample.input(), &mut gate, &mut pacer, &mut measured, &gauge_names, &settings.mount_height_m, now),
                        None => refuse_before_clock(&topic, &mut before_clock),
                    }
                }
                Err(e) => {
                    undecodable += 1;
                    log::warn!("{topic}: a sample could not be read: {e}");
                }
            },
            Some(sample) = fallback_rx.recv() => {
                recorder.input(&sample);
                take(sample.input(), &mut gate, &mut pacer, &mut measured, &gauge_names, &settings.mount_height_m, crate::twin::clock::system_s());
            }
            Some(report) = reports.recv() => {
                outstanding = outstanding.saturating_sub(1);
                let report: Report = report.map_err(|e| anyhow!("the solver stopped: {e}"))?;
                sim_t = report.obs.time_s;
                if report.reset {
                    // A new start: t = 0 is the next event; queued inputs belonged to the old run.
                    if !std::mem::take(&mut reset_by_clock) {
                        pacer = Pacer::new(pacer.target_rtf, pacer.stale_after_s, wait_for_sensors);
                        measured = vec![Readings::default(); gauge_names.len()];
                    }
                    println!("reset to the case's initial state");
                }
                solver_refused += report.refused_inflows;
                (frames_sent, frames_skipped) = (report.frames_sent, report.frames_skipped);
                period.add(&report);
                let Some(origin) = pacer.origin().or(clock.now()) else {
                    // Simulated time has not started: there is no time to stamp outputs with.
                    last_obs = report.obs;
                    continue;
                };
                let stamp = Time::from_secs_f64(origin + sim_t).unwrap_or_default();
                let header = Header { stamp, frame_id: settings.frame_id.clone() };
                if let Some(out) = &clock_out {
                    out.send(&mut recorder, Clock { clock: stamp }).await;
                }
                if let Some(points) = &report.cloud {
                    let cloud = visual::point_cloud(header.clone(), points, args.cloud_max_points);
                    cloud_out.send(&mut recorder, cloud).await;
                }
                // Outputs are decimated to the publish rate when the solver reports faster;
                // inputs never are.
                let due = last_publish
                    .is_none_or(|t| t.elapsed().as_secs_f64() >= 1.0 / settings.publish_rate_hz);
                let last = until.is_some_and(|u| sim_t >= u);
                if due || last {
                    last_publish = Some(Instant::now());
                    published_outputs += 1;
                    let now = clock.now();
                    let stale: Vec<bool> = measured
                        .iter()
                        .map(|m| match (m.newest(), now) {
                            (Some(t), Some(now)) => now - t > settings.stale_after_s,
                            _ => true,
                        })
                        .collect();
                    // Each gauge against its reading at the output's own time.
                    let at: Vec<Option<f64>> =
                        measured.iter_mut().map(|m| m.at(origin + sim_t)).collect();
                    let bed = bed_profile(&report.obs, header.clone());
                    marker_out.send(
                        &mut recorder,
                        visual::bed_lines(&header, &bed.x_m, &bed.zs_m, &bed.zw_m),
                    )
                    .await;
                    bed_out.send(&mut recorder, bed).await;
                    if let Some(msg) = eroded_mass(&report.obs, header.clone()) {
                        eroded_out.send(&mut recorder, msg).await;
                    }
                    compare_out.send(&mut recorder, comparison(&report.obs, &at, &stale, header)).await;
                } else {
                    decimated_outputs += 1;
                }
                last_obs = report.obs;
                if last {
                    println!("reached t = {sim_t:.3} s (--until)");
                    break;
                }
            }
            _ = tick.tick() => {
                let now_live = live.lock().unwrap_or_else(|p| p.into_inner()).clone();
                if now_live.target_rtf != pacer.target_rtf {
                    pacer.set_target_rtf(now_live.target_rtf);
                }
                pacer.stale_after_s = now_live.stale_after_s;
                settings = now_live;
                // Simulated time that has not started holds the twin.
                if let (0, false, Some(now)) = (outstanding, paused, clock.now()) {
                    let mut cap = args.max_chunk_s;
                    if let Some(u) = until {
                        cap = cap.min(u - sim_t);
                    }
                    if let Some(chunk) = pacer.next_chunk(sim_t, now, cap).filter(|_| cap > 0.0) {
                        let cloud = last_cloud
                            .is_none_or(|t| t.elapsed().as_secs_f64() >= 1.0 / args.cloud_rate_hz);
                        if cloud {
                            last_cloud = Some(Instant::now());
                        }
                        commands
                            .send(Command::Advance { to_s: chunk.to_s, inflow: chunk.inflow, cloud })
                            .map_err(|_| anyhow!("the solver thread has stopped"))?;
                        outstanding += 1;
                    }
                }
            }
            Some((which, request)) = service_requests.next() => {
                let Ok((id, _)) = request else {
                    log::warn!("a {which:?} request could not be read");
                    continue;
                };
                let (success, message) = match which {
                    Service::Pause => {
                        paused = true;
                        (true, format!("paused at t = {sim_t:.3} s; inputs are still taken"))
                    }
                    Service::Resume => {
                        paused = false;
                        pacer.set_target_rtf(pacer.target_rtf);
                        (true, format!("resumed at t = {sim_t:.3} s"))
                    }
                    Service::Step if !paused => (false, "pause the twin first".to_string()),
                    Service::Step if clock.now().is_none() => {
                        (false, "simulated time has not started: no /clock yet".to_string())
                    }
                    Service::Step => {
                        let chunk = pacer.step(sim_t, args.max_chunk_s);
                        let to = chunk.to_s;
                        commands
                            .send(Command::Advance { to_s: to, inflow: chunk.inflow, cloud: true })
                            .map_err(|_| anyhow!("the solver thread has stopped"))?;
                        outstanding += 1;
                        (true, format!("stepping from t = {sim_t:.3} s to {to:.3} s"))
                    }
                    Service::Reset => {
                        commands
                            .send(Command::Reset)
                            .map_err(|_| anyhow!("the solver thread has stopped"))?;
                        outstanding += 1;
                        (true, "resetting to the case's initial state".to_string())
                    }
                };
                println!("service {which:?}: {message}");
                let server = &servers[which as usize];
                if let Err(e) = server.async_send_response(id, TriggerResponse { success, message }).await {
                    log::warn!("the {which:?} response could not be sent: {e:?}");
                }
            }
            _ = diag_tick.tick() => {
                let now = clock.now();
                let stale: Vec<&str> = gauge_names
                    .iter()
                    .zip(&measured)
                    .filter(|(_, m)| match (m.newest(), now) {
                        (Some(t), Some(now)) => now - t > settings.stale_after_s,
                        _ => true,
                    })
                    .map(|(n, _)| n.as_str())
                    .collect();
                let lag = now.map_or(0.0, |now| pacer.lag(sim_t, now));
                let asked = node.get_parameter("use_sim_time");
                if asked.is_some_and(|v| v != ParameterValue::Boolean(settings.use_sim_time))
                    && !std::mem::replace(&mut sim_time_change_said, true)
                {
                    log::warn!(
                        "use_sim_time was changed on the running node: the twin keeps the clock it started with; restart it to change"
                    );
                }
                let (rtf, step_rate, busy) = period.take(sim_t);
                diag_count += 1;
                // A line on the terminal every ten seconds, for whoever started the twin by hand.
                if diag_count.is_multiple_of(10) {
                    let (rtf, _, _) = status_period.take(sim_t);
                    let levels: Vec<String> = gauge_names
                        .iter()
                        .zip(&last_obs.gauges)
                        .map(|(n, g)| format!("{n} {}", g.level_m.map_or("dry".into(), |l| format!("{l:.4} m"))))
                        .collect();
                    let eroded = last_obs.flume.as_ref().map_or(0.0, |f| f.eroded_kg);
                    println!(
                        "t = {sim_t:.2} s, {rtf:.3} x real time, {lag:.1} s behind; {}; eroded {eroded:.4} kg",
                        levels.join(", ")
                    );
                }
                let mut values = vec![
                    ("sim_time_s", format!("{sim_t:.6}")),
                    ("real_time_factor", format!("{rtf:.4}")),
                    ("target_real_time_factor", format!("{}", settings.target_rtf)),
                    ("lag_s", format!("{lag:.3}")),
                    ("step_rate_hz", format!("{step_rate:.1}")),
                    ("particles", particles.to_string()),
                    ("adapter", adapter.clone()),
                    ("solver_busy_fraction", format!("{busy:.3}")),
                    ("sensor_driven", now.is_some_and(|now| pacer.sensor_driven(now)).to_string()),
                    ("clock", if clock.simulated() { "/clock" } else { "system" }.to_string()),
                    ("inputs_before_clock", before_clock.to_string()),
                    ("paused", paused.to_string()),
                    ("stale_sensors", stale.join(",")),
                    ("rejected_inputs", gate.refused_total().to_string()),
                    ("undecodable_inputs", undecodable.to_string()),
                    ("solver_refused_inflows", solver_refused.to_string()),
                    ("late_inputs", pacer.late_inputs.to_string()),
                    ("published_outputs", published_outputs.to_string()),
                    ("decimated_outputs", decimated_outputs.to_string()),
                    ("recoveries", last_obs.recoveries.to_string()),
                    (
                        "excluded_particles",
                        last_obs.flume.as_ref().map_or(0, |f| f.excluded_particles).to_string(),
                    ),
                    ("particle_frames_sent", frames_sent.to_string()),
                    ("particle_frames_skipped", frames_skipped.to_string()),
                ];
                for (k, n) in gate.refused() {
                    values.push((k, n.to_string()));
                }
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
                diag_out.send(&mut recorder, DiagnosticArray {
                    header: Header { stamp, frame_id: String::new() },
                    status: vec![DiagnosticStatus {
                        level,
                        name: format!("{node_name}: twin"),
                        message,
                        hardware_id: adapter.clone(),
                        values: values
                            .into_iter()
                            .map(|(k, v)| KeyValue { key: k.to_string(), value: v })
                            .collect(),
                    }],
                }).await;
            }
        }
    }
    drop(commands);
    recorder.finish()?;
    // The solver finishes its chunk and sees the closed channel.
    if handle.join().is_err() {
        log::warn!("the solver thread panicked");
    }
    Ok(())
}

/// Gates a sensor sample; what passes goes to the pacer and to the gauge's readings.
fn take(
    input: Input,
    gate: &mut InputGate,
    pacer: &mut Pacer,
    measured: &mut [Readings],
    gauge_names: &[String],
    mount_height_m: &[f64],
    now: f64,
) {
    match input.admit(gate, gauge_names, mount_height_m, now) {
        Some(Admitted::Inflow { stamp_s, q }) => pacer.inflow(stamp_s, q),
        Some(Admitted::Level {
            index,
            stamp_s,
            level_m,
        }) => {
            pacer.heard(stamp_s);
            measured[index].push(stamp_s, level_m);
        }
        None => {}
    }
}

/// A sample that came before simulated time started: nothing can judge its stamp yet.
fn refuse_before_clock(topic: &str, count: &mut u64) {
    *count += 1;
    if *count == 1 {
        log::warn!(
            "{topic}: a sample came before the first /clock message (use_sim_time): refused, as are any more until /clock starts (counted in /diagnostics)"
        );
    }
}

/// With no sensor heard for `wait`, plays the inflow and gauge topics of the recording at
/// `path` as the sensors, at their recorded pace, restamped on this node's clock; stops at
/// the first sample a real sensor sends.
async fn play_when_silent(
    path: PathBuf,
    gauges: Vec<String>,
    wait: Duration,
    heard: Arc<AtomicBool>,
    to_twin: tokio::sync::mpsc::Sender<Sample>,
) {
    tokio::time::sleep(wait).await;
    if heard.load(Ordering::Relaxed) {
        return;
    }
    let read = tokio::task::spawn_blocking({
        let path = path.clone();
        move || BagFile::read(&path)
    })
    .await;
    let recording = match read {
        Ok(Ok(r)) => r,
        Ok(Err(e)) => {
            log::error!("no sensors, and the session to replay cannot be read: {e:#}");
            return;
        }
        Err(e) => {
            log::error!("no sensors, and reading the session to replay failed: {e}");
            return;
        }
    };
    if let Some(damage) = &recording.damage {
        log::warn!("{damage}; replaying what comes before it");
    }
    let mut samples: Vec<(u64, Sample)> = recording
        .messages
        .iter()
        .filter_map(|m| role(m, &gauges).map(|r| (m, r)))
        .filter_map(|(m, r)| match decode(m, r) {
            Ok(s) => Some((m.log_ns, s)),
            Err(e) => {
                log::warn!("{e:#}");
                None
            }
        })
        .collect();
    samples.sort_by_key(|(log_ns, _)| *log_ns);
    let Some(first) = samples.first().map(|(_, s)| s.stamp().as_secs_f64()) else {
        log::warn!(
            "{} has no sensor topic of this case to replay",
            path.display()
        );
        return;
    };
    let span = samples.last().map_or(0.0, |(_, s)| s.stamp().as_secs_f64()) - first;
    println!(
        "no sensors in {:.0} s: {} plays the sensors ({} samples over {span:.0} s)",
        wait.as_secs_f64(),
        path.display(),
        samples.len()
    );
    let start = crate::twin::clock::system_s();
    let started = Instant::now();
    for (_, mut sample) in samples {
        let offset = sample.stamp().as_secs_f64() - first;
        if let Some(rest) = Duration::from_secs_f64(offset.max(0.0)).checked_sub(started.elapsed())
        {
            tokio::time::sleep(rest).await;
        }
        if heard.load(Ordering::Relaxed) {
            println!("a sensor spoke: the recorded session stops");
            return;
        }
        sample.set_stamp(Time::from_secs_f64(start + offset).unwrap_or_default());
        if to_twin.send(sample).await.is_err() {
            return;
        }
    }
    println!("the recorded session has ended: the twin holds its last discharge");
}

/// The twin's services (std_srvs/Trigger), under the node's name; the order is that of the
/// servers.
#[derive(Debug, Clone, Copy)]
enum Service {
    Reset = 0,
    Pause = 1,
    Resume = 2,
    Step = 3,
}

impl Service {
    fn name(self) -> &'static str {
        match self {
            Service::Reset => "reset",
            Service::Pause => "pause",
            Service::Resume => "resume",
            Service::Step => "step",
        }
    }
}

/// Simulated time, steps and solver time over the last diagnostics period.
struct Period {
    started: Instant,
    sim_t0: f64,
    steps: u64,
    busy_s: f64,
}

impl Period {
    fn new(sim_t: f64) -> Period {
        Period {
            started: Instant::now(),
            sim_t0: sim_t,
            steps: 0,
            busy_s: 0.0,
        }
    }

    fn add(&mut self, report: &Report) {
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
