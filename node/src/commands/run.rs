//! `flume-twin run CASE [--ros-args ...]`: the twin as a ROS 2 node (ros2-client on tokio).
//!
//! Sensor samples come in on `inflow` and `gauges/<name>`, the solver's reports from its
//! thread, service calls and ticks from the node: each goes to the [`Twin`], and what it gives
//! back goes out as the bed profile, the eroded mass, the gauge comparison, `/clock` and, once
//! a second, `/diagnostics`. This module knows topics and times, not SPH.

use crate::adapters::bag::tap::{Outlet, Tap, input_channels};
use crate::adapters::files::outputs::recorder_in;
use crate::adapters::files::series_plot::SeriesPlots;
use crate::adapters::foxglove::{LiveView, ViewOptions};
use crate::adapters::frames::frames_on;
use crate::adapters::ros::args::RosArgs;
use crate::adapters::ros::parameters::{ParameterServices, ParameterStream, live_parameters};
use crate::adapters::ros::services::{Call, Offered};
use crate::adapters::ros::{dds_context, full_topic, outlet, qos, subscription};
use crate::adapters::topics;
use crate::cli::{GaugeMsg, RunArgs};
use crate::twin::gate::Limits;
use crate::twin::samples::Sample;
use crate::twin::settings::Settings;
use crate::twin::solver_thread::{self, ChunkSinks, Report};
use crate::twin::{Options, Published, Service, Twin, gauge_names};
use anyhow::{Context as _, Result, anyhow, bail};
use flume_msgs::diagnostic_msgs::DiagnosticArray;
use flume_msgs::flume_msgs::{BedProfile, Discharge, ErodedMass, GaugeComparison, WaterLevel};
use flume_msgs::rosgraph_msgs::Clock;
use flume_msgs::sensor_msgs::{PointCloud2, Range};
use flume_msgs::std_srvs::{TriggerRequest, TriggerResponse};
use flume_msgs::visualization_msgs::MarkerArray;
use flume_solver::Case;
use futures::stream::SelectAll;
use futures::{Stream, StreamExt};
use ros2_client::{Node, NodeName, NodeOptions, ParameterValue, ServiceTypeName, Subscription};
use std::path::PathBuf;
use std::pin::Pin;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Duration;
use tokio::sync::mpsc;

mod silence;

use silence::start_session_for_silence;

pub fn run(args: &RunArgs, ros_args: &[String]) -> Result<()> {
    let case = Case::from_path_with(&args.case, &args.set).context("the case file was refused")?;
    if case.open_flume.is_none() {
        bail!(
            "{}: the twin needs an open flume (open_flume: in the case) for its inflow to drive",
            args.case.display()
        );
    };
    let ros = RosArgs::parse(ros_args).context("bad --ros-args")?;
    let fqn = ros.node_fqn("flume_twin");
    let gauges: Vec<String> = gauge_names(&case)
        .iter()
        .map(|g| g.to_lowercase())
        .collect();
    let limits = Limits::for_case(&case, args.future_tolerance_s);
    // Range sensors are mounted at the flume's top unless a parameter says otherwise.
    let params = ros.parameters(&fqn)?;
    let settings = Settings::new(args.pace(), &gauges, limits.flume_height_m, &params)?;
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .enable_all()
        .build()
        .context("cannot start the async runtime")?;
    runtime.block_on(serve(args, case, ros, settings, limits))
}

/// Sets the node up on the wire around a new twin, then drives it.
async fn serve(
    args: &RunArgs,
    case: Case,
    ros: RosArgs,
    settings: Settings,
    limits: Limits,
) -> Result<()> {
    let namespace = ros.namespace.clone().unwrap_or_else(|| "/".into());
    let node_name = ros.node_name.clone().unwrap_or_else(|| "flume_twin".into());
    let gauge_names = gauge_names(&case);
    let sinks = ChunkSinks {
        recorder: args.out.clone().map(recorder_in),
        frames: (!args.no_frames)
            .then(|| frames_on(args.frames_service.clone(), args.frames_rate_hz)),
    };
    let case_name = case.name.clone();
    let solver = solver_thread::spawn(case, sinks)?;
    let (adapter, particles) = (&solver.link.adapter, solver.link.particles);
    println!("adapter: {adapter}\nparticles: {particles}\nnode: {namespace} {node_name}");
    let live = Arc::new(Mutex::new(settings.clone()));
    let context = dds_context(args.loopback, args.domain_id)?;
    let mut node = context
        .new_node(
            NodeName::new(&namespace, &node_name)
                .map_err(|e| anyhow!("node name {namespace} {node_name}: {e}"))?,
            live_parameters(NodeOptions::new().enable_rosout(true), &live),
        )
        .context("cannot create the ROS 2 node")?;
    let full = |name: &str| full_topic(&namespace, &ros, name);
    let use_sim_time = settings.use_sim_time;
    let sensors = Sensors::subscribe(&mut node, &full, &gauge_names, args.gauge_msg, use_sim_time)?;
    let mut tap = tap(args, &full, &gauge_names)?;
    let view_options = ViewOptions {
        port: args.foxglove,
        loopback: args.loopback,
        gauge_ranges: args.gauge_msg == GaugeMsg::Range,
    };
    let view = LiveView::for_node(&view_options, &full, &gauge_names).await?;
    let outlets = Outlets::create(&mut node, &mut tap, &view, &full, use_sim_time)?;
    let node_path = format!("{}/{node_name}", namespace.trim_end_matches('/'));
    let servers = services(&mut node, &node_path)?;
    let parameters = ParameterServices::create(&mut node, &node_path)?;
    let heard = Arc::new(AtomicBool::new(false));
    let (fallback, session_plays) =
        start_session_for_silence(args, &gauge_names, &heard, use_sim_time);
    // A player's clock may start before its first sample: t = 0 is the first sample.
    let wait_for_sensors = args.wait_for_sensors || session_plays || use_sim_time;
    println!(
        "listening: {} and {} gauge topics",
        full(topics::INFLOW),
        gauge_names.len()
    );
    let options = twin_options(args, gauge_names.clone(), node_path, wait_for_sensors);
    let mut twin = Twin::new(options, limits, settings, solver.link);
    let mut wire = Wire {
        node: &node,
        sensors: sensors.samples(&gauge_names),
        clock: sensors.clock(),
        requests: requests(&servers),
        servers: &servers,
        parameter_calls: parameters.calls(),
        parameters: &parameters,
        outlets,
        tap,
        view,
        heard,
        fallback,
        reports: solver.reports,
        live,
        plots: args.out.as_ref().map(|_| SeriesPlots::compared()),
    };
    drive(&mut twin, &mut wire).await?;
    // Closing the solver's channel: it finishes its chunk and stops.
    drop(twin);
    wind_down(wire, solver.handle, args.out.clone(), case_name).await
}

/// The live twin's options from the command line.
fn twin_options(
    args: &RunArgs,
    gauge_names: Vec<String>,
    node_name: String,
    wait_for_sensors: bool,
) -> Options {
    Options {
        gauge_names,
        node_name,
        wait_for_sensors,
        max_chunk_s: args.max_chunk_s,
        until: args.until,
        cloud_rate_hz: args.cloud_rate_hz,
        cloud_max_points: args.cloud_max_points,
    }
}

/// Closes the recording and the viewer, waits for the solver thread, and draws the plots
/// into `out`.
async fn wind_down(
    mut wire: Wire<'_>,
    solver: std::thread::JoinHandle<()>,
    out: Option<PathBuf>,
    case_name: String,
) -> Result<()> {
    wire.tap.finish()?;
    wire.view.stop().await;
    // Waiting for it is blocking work: off the async runtime's threads.
    let joined = tokio::task::spawn_blocking(move || solver.join()).await;
    if !matches!(joined, Ok(Ok(()))) {
        log::warn!("the solver thread panicked");
    }
    if let (Some(plots), Some(dir)) = (wire.plots.take(), out) {
        // Drawing and encoding PNGs is blocking work too.
        let drawn = tokio::task::spawn_blocking(move || plots.draw(&dir, &case_name))
            .await
            .context("drawing the plots failed")??;
        for path in drawn {
            println!("plot: {}", path.display());
        }
    }
    Ok(())
}

/// The node's recording (`--record`), its input channels opened for the sensors' topics.
fn tap(args: &RunArgs, full: &dyn Fn(&str) -> String, gauge_names: &[String]) -> Result<Tap> {
    let mut tap = Tap::create(args.record.as_deref())?;
    let gauge_topics: Vec<String> = gauge_names
        .iter()
        .map(|g| full(&topics::gauge(g)))
        .collect();
    let inputs = input_channels(
        &mut tap,
        &full(topics::INFLOW),
        &gauge_topics,
        args.gauge_msg == GaugeMsg::Range,
        topics::INFLOW_QOS,
        topics::GAUGE_QOS,
    )?;
    tap.set_inputs(inputs);
    Ok(tap)
}

/// The node's side while it runs: what it reads, and what it writes to.
struct Wire<'a> {
    node: &'a Node,
    sensors: SelectAll<SensorStream<'a>>,
    clock: ClockStream<'a>,
    requests: SelectAll<ServiceStream<'a>>,
    servers: &'a [TriggerServer],
    parameter_calls: SelectAll<ParameterStream<'a>>,
    parameters: &'a ParameterServices,
    outlets: Outlets,
    tap: Tap,
    view: LiveView,
    /// Set at the first sample a real sensor sends: a recorded session playing stops.
    heard: Arc<AtomicBool>,
    fallback: mpsc::Receiver<Sample>,
    reports: mpsc::UnboundedReceiver<Result<Report, String>>,
    live: Arc<Mutex<Settings>>,
    /// With `--out`: the published levels and eroded mass, drawn beside the CSV files at
    /// the end.
    plots: Option<SeriesPlots>,
}

/// Hands each event to the twin and sends what it gives back, until Ctrl-C, SIGTERM or
/// `--until`.
async fn drive(twin: &mut Twin, wire: &mut Wire<'_>) -> Result<()> {
    let mut shutdown = Box::pin(tokio::signal::ctrl_c());
    let mut terminate = tokio::signal::unix::signal(tokio::signal::unix::SignalKind::terminate())
        .context("cannot watch for SIGTERM")?;
    let mut tick = tokio::time::interval(Duration::from_millis(20));
    let mut status_tick = tokio::time::interval(Duration::from_secs(1));
    let mut sim_time_change_said = false;
    loop {
        tokio::select! {
            // In order: a player sends /clock just before a sample, on another writer, and
            // the sample is judged on that clock. Nothing here comes fast enough to starve
            // the branches after it.
            biased;
            _ = &mut shutdown => {
                println!("interrupted at t = {:.3} s", twin.sim_t());
                return Ok(());
            }
            _ = terminate.recv() => {
                println!("terminated at t = {:.3} s", twin.sim_t());
                return Ok(());
            }
            Some(r) = wire.clock.next() => match r {
                Ok(t) => twin.clock(t)?,
                Err(e) => log::warn!("/clock: a message could not be read: {e}"),
            },
            Some((topic, r)) = wire.sensors.next() => match r {
                Ok(sample) => {
                    if !wire.heard.swap(true, Ordering::Relaxed) {
                        println!("sensors heard on {topic}");
                    }
                    wire.tap.input(&sample);
                    wire.view.input(&sample);
                    twin.sample(&topic, &sample);
                }
                Err(e) => twin.undecodable(&topic, &e),
            },
            Some(sample) = wire.fallback.recv() => {
                wire.tap.input(&sample);
                wire.view.input(&sample);
                twin.sample_at(sample.input(), crate::twin::clock::system_s());
            }
            Some(report) = wire.reports.recv() => {
                let report = report.map_err(|e| anyhow!("the solver stopped: {e}"))?;
                if let Some(out) = twin.report(report) {
                    let last = out.last;
                    if let (Some(plots), Some(o)) = (wire.plots.as_mut(), &out.outputs) {
                        plots.compare(twin.sim_t(), &o.comparison, o.eroded.as_ref());
                    }
                    wire.outlets.publish(&mut wire.tap, out).await;
                    if last {
                        println!("reached t = {:.3} s (--until)", twin.sim_t());
                        return Ok(());
                    }
                }
            }
            _ = tick.tick() => {
                let live = wire.live.lock().unwrap_or_else(|p| p.into_inner()).clone();
                twin.tick(live)?;
            }
            Some((which, call)) = wire.requests.next() => respond(twin, wire.servers, which, call).await?,
            Some(call) = wire.parameter_calls.next() => {
                wire.parameters.answer(wire.node, &wire.live, call).await;
            }
            _ = status_tick.tick() => {
                let kept = twin.settings().use_sim_time;
                warn_sim_time_change(wire.node, kept, &mut sim_time_change_said);
                let status = twin.status();
                wire.outlets.diagnostics.send(&mut wire.tap, status).await;
            }
        }
    }
}

/// Answers a service call with what the twin did.
async fn respond(
    twin: &mut Twin,
    servers: &[TriggerServer],
    which: Service,
    call: Call<TriggerRequest>,
) -> Result<()> {
    let (success, message) = twin.service(which)?;
    println!("service {which:?}: {message}");
    let response = TriggerResponse { success, message };
    servers[which as usize]
        .reply(call.mapping, call.id, response)
        .await;
    Ok(())
}

/// ROS lets `use_sim_time` change on a running node; the twin keeps the clock it started
/// with, and says so once.
fn warn_sim_time_change(node: &Node, kept: bool, said: &mut bool) {
    let asked = node.get_parameter("use_sim_time");
    if asked.is_some_and(|v| v != ParameterValue::Boolean(kept)) && !std::mem::replace(said, true) {
        log::warn!(
            "use_sim_time was changed on the running node: the twin keeps the clock it started with; restart it to change"
        );
    }
}

/// Every sensor topic as one stream of (topic, sample or why it could not be read).
type SensorStream<'a> = Pin<Box<dyn Stream<Item = (String, Result<Sample, String>)> + Send + 'a>>;
/// `/clock`'s times, or why a message could not be read.
type ClockStream<'a> = Pin<Box<dyn Stream<Item = Result<f64, String>> + Send + 'a>>;
/// Service calls: which, and the call.
type ServiceStream<'a> = Pin<Box<dyn Stream<Item = (Service, Call<TriggerRequest>)> + Send + 'a>>;
type TriggerServer = Offered<TriggerRequest, TriggerResponse>;

/// The sensors' subscriptions: the inflow, each gauge (as levels or as ranges) and, on
/// simulated time, `/clock`.
struct Sensors {
    inflow: Subscription<Discharge>,
    levels: Vec<Subscription<WaterLevel>>,
    ranges: Vec<Subscription<Range>>,
    clock: Option<Subscription<Clock>>,
}

impl Sensors {
    fn subscribe(
        node: &mut Node,
        full: &dyn Fn(&str) -> String,
        gauge_names: &[String],
        gauge_msg: GaugeMsg,
        use_sim_time: bool,
    ) -> Result<Sensors> {
        let gauge_qos = qos(topics::GAUGE_QOS);
        let mut sensors = Sensors {
            inflow: subscription(node, full, topics::INFLOW, qos(topics::INFLOW_QOS))?,
            levels: Vec::new(),
            ranges: Vec::new(),
            // ros2-client's own simulated time listens to /clock as builtin_interfaces/Time,
            // which a player's rosgraph_msgs/Clock does not match; the node keeps its own.
            clock: use_sim_time
                .then(|| subscription(node, full, topics::CLOCK, qos(topics::STREAM_QOS)))
                .transpose()?,
        };
        for g in gauge_names {
            let topic = topics::gauge(g);
            match gauge_msg {
                GaugeMsg::WaterLevel => {
                    sensors
                        .levels
                        .push(subscription(node, full, &topic, gauge_qos.clone())?)
                }
                GaugeMsg::Range => {
                    sensors
                        .ranges
                        .push(subscription(node, full, &topic, gauge_qos.clone())?)
                }
            }
        }
        Ok(sensors)
    }

    fn samples(&self, gauge_names: &[String]) -> SelectAll<SensorStream<'_>> {
        let error = |e: ros2_client::ReadError| format!("{e:?}");
        let mut streams: Vec<SensorStream> =
            vec![Box::pin(self.inflow.async_stream().map(move |r| {
                let sample = r.map(|(m, _)| Sample::Inflow(m)).map_err(error);
                ("inflow".to_string(), sample)
            }))];
        for (i, s) in self.levels.iter().enumerate() {
            let name = gauge_names[i].clone();
            streams.push(Box::pin(s.async_stream().map(move |r| {
                let sample = r.map(|(m, _)| Sample::Level(i, m)).map_err(error);
                (name.clone(), sample)
            })));
        }
        for (i, s) in self.ranges.iter().enumerate() {
            let name = gauge_names[i].clone();
            streams.push(Box::pin(s.async_stream().map(move |r| {
                let sample = r.map(|(m, _)| Sample::Range(i, m)).map_err(error);
                (name.clone(), sample)
            })));
        }
        futures::stream::select_all(streams)
    }

    fn clock(&self) -> ClockStream<'_> {
        match &self.clock {
            Some(sub) => Box::pin(sub.async_stream().map(|r| {
                r.map(|(c, _)| c.clock.as_secs_f64())
                    .map_err(|e| format!("{e:?}"))
            })),
            None => Box::pin(futures::stream::pending()),
        }
    }
}

/// The twin's publishers, each recorded through the tap when the node records.
struct Outlets {
    bed: Outlet<BedProfile>,
    eroded: Outlet<ErodedMass>,
    compare: Outlet<GaugeComparison>,
    /// None on simulated time: the player owns /clock.
    clock: Option<Outlet<Clock>>,
    diagnostics: Outlet<DiagnosticArray>,
    cloud: Outlet<PointCloud2>,
    marker: Outlet<MarkerArray>,
}

impl Outlets {
    fn create(
        node: &mut Node,
        tap: &mut Tap,
        view: &LiveView,
        full: &dyn Fn(&str) -> String,
        use_sim_time: bool,
    ) -> Result<Outlets> {
        use topics::{BED_MARKER, BED_PROFILE, CLOCK, DIAGNOSTICS, ERODED_MASS, PARTICLES};
        use topics::{GAUGE_COMPARISON, LATCHED_QOS, OUTPUT_QOS, STREAM_QOS};
        Ok(Outlets {
            bed: outlet(node, tap, view, full, BED_PROFILE, LATCHED_QOS)?,
            eroded: outlet(node, tap, view, full, ERODED_MASS, OUTPUT_QOS)?,
            compare: outlet(node, tap, view, full, GAUGE_COMPARISON, OUTPUT_QOS)?,
            clock: (!use_sim_time)
                .then(|| outlet(node, tap, view, full, CLOCK, STREAM_QOS))
                .transpose()?,
            diagnostics: outlet(node, tap, view, full, DIAGNOSTICS, OUTPUT_QOS)?,
            cloud: outlet(node, tap, view, full, PARTICLES, STREAM_QOS)?,
            marker: outlet(node, tap, view, full, BED_MARKER, LATCHED_QOS)?,
        })
    }

    /// What the twin gave back after a report, in the order a listener expects it.
    async fn publish(&self, tap: &mut Tap, out: Published) {
        if let Some(o) = &self.clock {
            o.send(tap, out.clock).await;
        }
        if let Some(cloud) = out.cloud {
            self.cloud.send(tap, cloud).await;
        }
        if let Some(o) = out.outputs {
            self.marker.send(tap, o.marker).await;
            self.bed.send(tap, o.bed).await;
            if let Some(msg) = o.eroded {
                self.eroded.send(tap, msg).await;
            }
            self.compare.send(tap, o.comparison).await;
        }
    }
}

/// The twin's services (std_srvs/Trigger) under the node's name, in [`Service::ALL`]'s order.
fn services(node: &mut Node, node_path: &str) -> Result<Vec<TriggerServer>> {
    Service::ALL
        .iter()
        .map(|s| {
            let kind = ServiceTypeName::new("std_srvs", "Trigger");
            Offered::create(node, node_path, s.name(), &kind, &qos(topics::OUTPUT_QOS))
        })
        .collect()
}

fn requests(servers: &[TriggerServer]) -> SelectAll<ServiceStream<'_>> {
    futures::stream::select_all(
        servers.iter().zip(Service::ALL).map(|(srv, which)| {
            Box::pin(srv.calls().map(move |call| (which, call))) as ServiceStream
        }),
    )
}
