//! `flume-twin replay REC --publish`: a recorded session's sensor topics played on the
//! wire (ROS 2 over DDS) with `/clock`, as `ros2 bag play --clock` does, for a twin (or any
//! ROS node) running on simulated time (`use_sim_time:=true`) elsewhere.
//!
//! Samples go out unchanged (their stamps are the recording's) when the player's clock
//! reaches their log time; `/clock` carries that clock `--clock-hz` times a wall second and
//! just before each sample (so that a node on simulated time never sees a sample ahead of its
//! clock by more than the sample's own lead), and holds at the start for `--delay-s` so that
//! subscribers match before the first sample. The topics' QoS is the twin's table's
//! (`topics.rs`), which is what our recordings offer.

use crate::adapters::bag::{BagFile, BagMessage};
use crate::adapters::ros::args::RosArgs;
use crate::adapters::ros::{dds_context, full_topic, qos, topic_name, type_name};
use crate::adapters::topics;
use crate::cli::ReplayArgs;
use anyhow::{Context as _, Result, anyhow, bail};
use flume_msgs::RosMessage;
use flume_msgs::builtin_interfaces::Time;
use flume_msgs::flume_msgs::{Discharge, WaterLevel};
use flume_msgs::rosgraph_msgs::Clock;
use flume_msgs::sensor_msgs::Range;
use ros2_client::{Node, NodeName, NodeOptions, Publisher};
use serde::Serialize;
use std::collections::BTreeMap;
use std::time::{Duration, Instant};

/// A sensor topic's publisher.
enum Wire {
    Inflow(Publisher<Discharge>),
    Level(Publisher<WaterLevel>),
    Range(Publisher<Range>),
}

/// A sample's message, by type.
enum Payload {
    Inflow(Discharge),
    Level(WaterLevel),
    Range(Range),
}

/// A sample to play: its publisher (by index), its log time (s) and the message.
struct Due {
    wire: usize,
    at_s: f64,
    payload: Payload,
}

fn publisher<M: RosMessage + Serialize>(
    node: &mut Node,
    ros: &RosArgs,
    topic: &str,
    topic_qos: crate::adapters::bag::TopicQos,
) -> Result<Publisher<M>> {
    let q = qos(topic_qos);
    let t = node
        .create_topic(
            &topic_name(&full_topic("/", ros, topic))?,
            type_name(M::DEF),
            &q,
        )
        .with_context(|| format!("cannot create topic {topic}"))?;
    node.create_publisher::<M>(&t, Some(q))
        .with_context(|| format!("cannot publish {topic}"))
}

/// Whether `m` is a sensor's: a discharge, a level or a range.
fn is_sensor(m: &BagMessage) -> bool {
    [Discharge::DEF, WaterLevel::DEF, Range::DEF]
        .iter()
        .any(|d| m.schema_name == d.schema_name())
}

/// A sensor's message decoded (see [`is_sensor`]).
fn payload(m: &BagMessage) -> Result<Payload> {
    let s = m.schema_name.as_str();
    if s == Discharge::DEF.schema_name() {
        m.decode().map(Payload::Inflow)
    } else if s == WaterLevel::DEF.schema_name() {
        m.decode().map(Payload::Level)
    } else {
        m.decode().map(Payload::Range)
    }
}

pub fn run(args: &ReplayArgs, ros_args: &[String]) -> Result<()> {
    let ros = RosArgs::parse(ros_args).context("bad --ros-args")?;
    if ros.namespace.is_some()
        || ros.node_name.is_some()
        || !ros.params.is_empty()
        || !ros.params_files.is_empty()
    {
        log::warn!(
            "the player takes topic remaps only: its namespace, node name and parameters are ignored"
        );
    }
    let recording = BagFile::read(&args.recording)?;
    if let Some(damage) = &recording.damage {
        log::warn!("{damage}; playing what comes before it");
        eprintln!("warning: {damage}; playing what comes before it");
    }
    let sensors = sensor_messages(args, &recording)?;
    let start_s = sensors[0].log_ns as f64 * 1e-9 + args.start_s;
    let end_s = args.until.map_or(f64::INFINITY, |u| start_s + u);
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .enable_all()
        .build()
        .context("cannot start the async runtime")?;
    runtime.block_on(async {
        let context = dds_context(args.loopback, args.domain_id)?;
        let mut node = context
            .new_node(
                NodeName::new("/", "flume_twin_player")
                    .map_err(|e| anyhow!("node name: {e}"))?,
                NodeOptions::new(),
            )
            .context("cannot create the ROS 2 node")?;
        // No spinner: it serves only parameters, which the player has none of, and it
        // subscribes /clock as builtin_interfaces/Time, a clash with the player's
        // rosgraph_msgs/Clock that RustDDS reports as an error.
        let clock = publisher::<Clock>(&mut node, &ros, topics::CLOCK, topics::STREAM_QOS)?;
        let plan = Plan::build(&mut node, &ros, sensors, start_s..=end_s)?;
        if plan.due.is_empty() {
            bail!(
                "nothing to play between {} s and {} s into the recording",
                args.start_s,
                args.start_s + args.until.unwrap_or(f64::INFINITY)
            );
        }
        let player = Player {
            clock,
            period: Duration::from_secs_f64(1.0 / args.clock_hz),
            rate: args.rate.unwrap_or(1.0),
            start_s,
        };
        println!(
            "playing {} samples on {} topics, {:.1} s of the recording from {start_s:.3} s since the epoch, at {} x, /clock at {} Hz",
            plan.due.len(),
            plan.wires.len(),
            plan.last_s(start_s) - start_s,
            player.rate,
            args.clock_hz,
        );
        player.play(&plan, args.delay_s).await
    })
}

/// The recording's sensor messages on the topics asked for, in log-time order, at least one;
/// the count of every other topic's messages printed.
fn sensor_messages<'a>(args: &ReplayArgs, recording: &'a BagFile) -> Result<Vec<&'a BagMessage>> {
    let selected = |topic: &str| args.topics.is_empty() || args.topics.iter().any(|t| t == topic);
    let mut sensors: Vec<&BagMessage> = Vec::new();
    let mut ignored: BTreeMap<&str, u64> = BTreeMap::new();
    for m in &recording.messages {
        if is_sensor(m) && selected(&m.topic) {
            sensors.push(m);
        } else {
            *ignored.entry(&m.topic).or_default() += 1;
        }
    }
    for (topic, n) in &ignored {
        println!("not played: {topic} ({n} messages)");
    }
    sensors.sort_by_key(|m| m.log_ns);
    if sensors.is_empty() {
        bail!(
            "{} holds no inflow or gauge topic to play{}",
            args.recording.display(),
            if args.topics.is_empty() {
                ""
            } else {
                " among --topics"
            }
        );
    }
    Ok(sensors)
}

/// What is to be played: a publisher per topic, and the samples in order.
struct Plan {
    wires: Vec<Wire>,
    due: Vec<Due>,
    /// Samples that could not be decoded (logged, not played).
    undecodable: u64,
}

impl Plan {
    /// The samples logged within `window` (s since the epoch), decoded, a publisher created
    /// for each topic as it first comes.
    fn build(
        node: &mut Node,
        ros: &RosArgs,
        sensors: Vec<&BagMessage>,
        window: std::ops::RangeInclusive<f64>,
    ) -> Result<Plan> {
        let mut plan = Plan {
            wires: Vec::new(),
            due: Vec::new(),
            undecodable: 0,
        };
        let mut index: BTreeMap<&str, usize> = BTreeMap::new();
        for m in sensors {
            let at_s = m.log_ns as f64 * 1e-9;
            if !window.contains(&at_s) {
                continue;
            }
            let payload = match payload(m) {
                Ok(p) => p,
                Err(e) => {
                    plan.undecodable += 1;
                    log::warn!("{e:#}");
                    continue;
                }
            };
            let t = m.topic.as_str();
            let wire = match index.get(t) {
                Some(&k) => k,
                None => {
                    plan.wires.push(match payload {
                        Payload::Inflow(_) => {
                            Wire::Inflow(publisher(node, ros, t, topics::INFLOW_QOS)?)
                        }
                        Payload::Level(_) => {
                            Wire::Level(publisher(node, ros, t, topics::GAUGE_QOS)?)
                        }
                        Payload::Range(_) => {
                            Wire::Range(publisher(node, ros, t, topics::GAUGE_QOS)?)
                        }
                    });
                    println!("playing {t} as {}", full_topic("/", ros, t));
                    index.insert(t, plan.wires.len() - 1);
                    plan.wires.len() - 1
                }
            };
            plan.due.push(Due {
                wire,
                at_s,
                payload,
            });
        }
        Ok(plan)
    }

    /// The last sample's log time, s since the epoch (`start_s` with none).
    fn last_s(&self, start_s: f64) -> f64 {
        self.due.last().map_or(start_s, |d| d.at_s)
    }

    /// Publishes sample `d` on its topic, logging what could not be sent.
    fn send(&self, d: &Due) {
        let r = match (&self.wires[d.wire], &d.payload) {
            (Wire::Inflow(p), Payload::Inflow(m)) => p.publish(m.clone()).map_err(drop),
            (Wire::Level(p), Payload::Level(m)) => p.publish(m.clone()).map_err(drop),
            (Wire::Range(p), Payload::Range(m)) => p.publish(m.clone()).map_err(drop),
            _ => {
                log::warn!(
                    "a sample logged at {:.3} s has another type than its topic's first: not sent",
                    d.at_s
                );
                Ok(())
            }
        };
        if r.is_err() {
            log::warn!("a sample logged at {:.3} s could not be sent", d.at_s);
        }
    }
}

/// The player's clock: `/clock` every `period` of wall time, the recording's time running
/// `rate` times as fast as the wall's from `start_s` (s since the epoch).
struct Player {
    clock: Publisher<Clock>,
    period: Duration,
    rate: f64,
    start_s: f64,
}

impl Player {
    fn send_clock(&self, t: f64) {
        let stamp = Time::from_secs_f64(t).unwrap_or_default();
        if let Err(e) = self.clock.publish(Clock { clock: stamp }) {
            log::warn!("/clock could not be sent: {e:?}");
        }
    }

    /// Holds the clock at the start for `delay_s`, then plays the plan to its end, Ctrl-C or
    /// SIGTERM.
    async fn play(&self, plan: &Plan, delay_s: f64) -> Result<()> {
        let mut shutdown = Box::pin(tokio::signal::ctrl_c());
        let mut terminate =
            tokio::signal::unix::signal(tokio::signal::unix::SignalKind::terminate())
                .context("cannot watch for SIGTERM")?;
        let held = Instant::now();
        while held.elapsed().as_secs_f64() < delay_s.max(0.0) {
            self.send_clock(self.start_s);
            tokio::select! {
                _ = tokio::time::sleep(self.period) => {}
                _ = &mut shutdown => return Ok(()),
                _ = terminate.recv() => return Ok(()),
            }
        }
        let (start_s, last_s) = (self.start_s, plan.last_s(self.start_s));
        let started = Instant::now();
        let mut next_clock = started;
        let (mut sent, mut clocks) = (0usize, 0u64);
        while sent < plan.due.len() {
            let now_s = (start_s + started.elapsed().as_secs_f64() * self.rate).min(last_s);
            let due = plan.due.get(sent).is_some_and(|d| d.at_s <= now_s);
            if due || Instant::now() >= next_clock {
                self.send_clock(now_s);
                clocks += 1;
                // After a stall the clock goes on from now rather than catching up in a burst.
                next_clock = (next_clock + self.period).max(Instant::now());
            }
            while let Some(d) = plan.due.get(sent).filter(|d| d.at_s <= now_s) {
                plan.send(d);
                sent += 1;
            }
            let next_sample = plan.due.get(sent).map_or(next_clock, |d| {
                started + Duration::from_secs_f64((d.at_s - start_s) / self.rate)
            });
            tokio::select! {
                _ = tokio::time::sleep_until(next_clock.min(next_sample).into()) => {}
                _ = &mut shutdown => {
                    println!("interrupted at {:.3} s of the recording", now_s - start_s);
                    return Ok(());
                }
                _ = terminate.recv() => {
                    println!("terminated at {:.3} s of the recording", now_s - start_s);
                    return Ok(());
                }
            }
        }
        self.send_clock(last_s);
        let wall = started.elapsed().as_secs_f64();
        // Reliable samples still in flight get their chance before the writers go.
        tokio::time::sleep(Duration::from_millis(200)).await;
        println!(
            "played {sent} samples and {} /clock messages in {wall:.3} s; undecodable: {}",
            clocks + 1,
            plan.undecodable,
        );
        Ok(())
    }
}
