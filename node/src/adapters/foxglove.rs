//! The live view in Foxglove (`run --foxglove PORT`): the Foxglove WebSocket protocol, served
//! by the Foxglove SDK. Every topic the node publishes or hears is a channel of the same full
//! name, with the `ros2msg` schema and the `cdr` messages the recordings carry, so the Foxglove
//! app shows the twin as it shows a ROS 2 bridge, with no ROS installed.
//!
//! A viewer never slows the twin. Logging a message on a channel does not wait on any client:
//! the SDK frames it (a copy) for each subscribed client and `try_send`s it into that client's
//! bounded queue (`flume::bounded(BACKLOG)`); when the queue is full it drops the oldest message
//! and tries again (`send_lossy`), and a client whose control queue fills is disconnected. A
//! stalled client therefore costs one copy of each message and at most `BACKLOG` messages of
//! memory; a channel no client subscribes to costs nothing, not even the encoding.

use crate::adapters::bag::writer::nanos;
use crate::adapters::topics;
use crate::twin::samples::Sample;
use anyhow::{Context as _, Result};
use flume_msgs::RosMessage;
use flume_msgs::flume_msgs::{Discharge, WaterLevel};
use flume_msgs::sensor_msgs::Range;
use foxglove::{ChannelBuilder, Context, PartialMetadata, RawChannel, Schema, WebSocketServer};
use serde::Serialize;
use std::sync::Arc;

/// Messages queued per client before the oldest are dropped. The node sends some tens of
/// messages a second (a clock per solver report, the outputs at the publish rate, a cloud at
/// the cloud rate): this is several seconds of them, enough to ride out a client's hiccup,
/// while a stalled client holds at most this many (even were all clouds of the default
/// 20,000 points, 400 KB each, about 100 MB).
const BACKLOG: usize = 256;

/// The server and the channels it offers, or nothing when the node runs without a viewer.
pub struct LiveView {
    server: Option<Server>,
    /// The inflow's channel, then each gauge's, as the recording's inputs.
    inputs: Vec<Option<LiveChannel>>,
}

struct Server {
    context: Arc<Context>,
    handle: foxglove::WebSocketServerHandle,
}

/// One topic's channel.
pub struct LiveChannel(Arc<RawChannel>);

/// Where the live view serves and how the gauges' topics read.
pub struct ViewOptions {
    /// The port (0: one the system picks), or none for no viewer.
    pub port: Option<u16>,
    /// Serve on the loopback interface only.
    pub loopback: bool,
    /// The gauges publish ultrasonic ranges (sensor_msgs/Range), not levels.
    pub gauge_ranges: bool,
}

impl LiveView {
    /// Serves on `port` (0: one the system picks) when there is one: on the loopback
    /// interface only when `loopback`, as DDS, otherwise on every interface, as the ROS
    /// topics are. Prints the address a client connects to.
    async fn start(port: Option<u16>, loopback: bool) -> Result<LiveView> {
        let Some(port) = port else {
            return Ok(LiveView {
                server: None,
                inputs: Vec::new(),
            });
        };
        let host = if loopback { "127.0.0.1" } else { "0.0.0.0" };
        let context = Context::new();
        // No capability beyond subscribing: a viewer cannot publish, call or set anything.
        let handle = WebSocketServer::new()
            .name(concat!("flume-twin ", env!("CARGO_PKG_VERSION")))
            .message_backlog_size(BACKLOG)
            .context(&context)
            .bind(host, port)
            .start()
            .await
            .with_context(|| format!("cannot serve Foxglove's WebSocket on {host}:{port}"))?;
        println!("foxglove: ws://{host}:{}", handle.port());
        Ok(LiveView {
            server: Some(Server { context, handle }),
            inputs: Vec::new(),
        })
    }

    /// A channel for `M` on `topic` (the full name), when serving.
    pub fn channel<M: RosMessage>(&self, topic: &str) -> Result<Option<LiveChannel>> {
        let Some(server) = &self.server else {
            return Ok(None);
        };
        let schema = Schema::new(
            M::DEF.schema_name(),
            "ros2msg",
            M::DEF.full_text().into_bytes(),
        );
        let channel = ChannelBuilder::new(topic)
            .message_encoding("cdr")
            .schema(schema)
            .context(&server.context)
            .build_raw()
            .with_context(|| format!("cannot offer {topic} to Foxglove"))?;
        Ok(Some(LiveChannel(channel)))
    }

    /// The node's live view (`--foxglove`), with channels for the sensors' topics: the
    /// inflow's, then the gauges' in the case's order, as levels or as ranges.
    pub async fn for_node(
        options: &ViewOptions,
        full: &dyn Fn(&str) -> String,
        gauge_names: &[String],
    ) -> Result<LiveView> {
        let mut view = LiveView::start(options.port, options.loopback).await?;
        let mut inputs = vec![view.channel::<Discharge>(&full(topics::INFLOW))?];
        for g in gauge_names {
            let topic = full(&topics::gauge(g));
            inputs.push(if options.gauge_ranges {
                view.channel::<Range>(&topic)?
            } else {
                view.channel::<WaterLevel>(&topic)?
            });
        }
        view.inputs = inputs;
        Ok(view)
    }

    /// Shows a sample the twin took, on its sensor's channel.
    pub fn input(&self, sample: &Sample) {
        let channel = |k: usize| self.inputs.get(k).and_then(Option::as_ref);
        match sample {
            Sample::Inflow(m) => channel(0).map(|c| c.log(m)),
            Sample::Level(g, m) => channel(g + 1).map(|c| c.log(m)),
            Sample::Range(g, m) => channel(g + 1).map(|c| c.log(m)),
        };
    }

    /// Closes every client's connection, waiting at most a second: a stalled client's
    /// tasks are then cut off.
    pub async fn stop(self) {
        if let Some(server) = self.server {
            let closing = server.handle.stop().wait();
            let _ = tokio::time::timeout(std::time::Duration::from_secs(1), closing).await;
        }
    }
}

impl LiveChannel {
    /// Sends `msg` to the clients subscribed to this channel, if any, without waiting on them.
    pub fn log<M: Serialize>(&self, msg: &M) {
        if !self.0.has_sinks() {
            return;
        }
        match cdr::serialize::<_, _, cdr::CdrLe>(msg, cdr::Infinite) {
            Ok(data) => {
                let now = nanos(crate::twin::clock::system_s());
                self.0.log_with_meta(
                    &data,
                    PartialMetadata {
                        log_time: Some(now),
                    },
                );
            }
            Err(e) => log::warn!("{}: cannot encode for Foxglove: {e}", self.0.topic()),
        }
    }
}
