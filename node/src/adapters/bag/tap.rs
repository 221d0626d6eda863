//! The node's own recording (`run --record BAG`, a bag directory or a FILE.mcap): every sample
//! that came in and every message that went out, as it happened (log time = the node's clock
//! when it was taken or sent), with rosbag2's conventions. Chunks close each second, so
//! `kill -9` loses at most the last second; SIGINT and SIGTERM finish the file. A recording
//! that cannot be written is stopped with an error line; the twin runs on.

use crate::adapters::bag::writer::{Channel, nanos};
use crate::adapters::bag::{BagWriter, TopicQos};
use crate::adapters::foxglove::LiveChannel;
use crate::twin::samples::Sample;
use anyhow::Result;
use flume_msgs::RosMessage;
use flume_msgs::flume_msgs::{Discharge, WaterLevel};
use flume_msgs::sensor_msgs::Range;
use ros2_client::Publisher;
use serde::Serialize;
use std::path::Path;
use std::time::Duration;

pub struct Tap {
    bag: Option<BagWriter>,
    /// The inflow's channel, then each gauge's.
    inputs: Vec<Option<Channel>>,
}

impl Tap {
    /// A recording to `path`, or none.
    pub fn create(path: Option<&Path>) -> Result<Tap> {
        let bag = path
            .map(|p| BagWriter::create(p, Some(Duration::from_secs(1))))
            .transpose()?;
        Ok(Tap {
            bag,
            inputs: Vec::new(),
        })
    }

    /// A channel for `M` on `topic` (the full name), when recording.
    pub fn channel<M: RosMessage>(
        &mut self,
        topic: &str,
        qos: TopicQos,
    ) -> Result<Option<Channel>> {
        self.bag
            .as_mut()
            .map(|b| b.channel::<M>(topic, qos))
            .transpose()
    }

    /// The input channels: the inflow's, then the gauges' in the case's order.
    pub fn set_inputs(&mut self, inputs: Vec<Option<Channel>>) {
        self.inputs = inputs;
    }

    pub fn input(&mut self, sample: &Sample) {
        let now = nanos(crate::twin::clock::system_s());
        let sent = sample.stamp().as_nanos().unwrap_or(now);
        let (k, result) = match sample {
            Sample::Inflow(m) => (0, self.write_to(0, m, now, sent)),
            Sample::Level(g, m) => (g + 1, self.write_to(g + 1, m, now, sent)),
            Sample::Range(g, m) => (g + 1, self.write_to(g + 1, m, now, sent)),
        };
        if let Err(e) = result {
            self.stop(&format!("input {k}: {e:#}"));
        }
    }

    fn write_to<M: Serialize>(&mut self, k: usize, msg: &M, log: u64, sent: u64) -> Result<()> {
        match (self.bag.as_mut(), self.inputs.get(k).copied().flatten()) {
            (Some(bag), Some(ch)) => bag.write(ch, msg, log, sent),
            _ => Ok(()),
        }
    }

    fn output<M: Serialize>(&mut self, channel: Option<Channel>, msg: &M) {
        let (Some(bag), Some(ch)) = (self.bag.as_mut(), channel) else {
            return;
        };
        let now = nanos(crate::twin::clock::system_s());
        if let Err(e) = bag.write(ch, msg, now, now) {
            self.stop(&format!("{e:#}"));
        }
    }

    fn stop(&mut self, why: &str) {
        if let Some(bag) = self.bag.take() {
            log::error!(
                "the recording {} stopped: {why}; the twin runs on",
                bag.path().display()
            );
        }
    }

    /// Finishes the file (summary and footer).
    pub fn finish(self) -> Result<()> {
        match self.bag {
            Some(bag) => {
                let path = bag.path().display().to_string();
                bag.finish()?;
                println!("recorded {path}");
                Ok(())
            }
            None => Ok(()),
        }
    }
}

/// The recorded types of the inputs, for [`Tap::set_inputs`].
pub fn input_channels(
    tap: &mut Tap,
    inflow_topic: &str,
    gauge_topics: &[String],
    ranges: bool,
    inflow_qos: TopicQos,
    gauge_qos: TopicQos,
) -> Result<Vec<Option<Channel>>> {
    let mut out = vec![tap.channel::<Discharge>(inflow_topic, inflow_qos)?];
    for t in gauge_topics {
        out.push(if ranges {
            tap.channel::<Range>(t, gauge_qos)?
        } else {
            tap.channel::<WaterLevel>(t, gauge_qos)?
        });
    }
    Ok(out)
}

/// A publisher and, when the node records, its channel; when it serves Foxglove, its live
/// channel.
pub struct Outlet<M: Serialize> {
    pub publisher: Publisher<M>,
    pub channel: Option<Channel>,
    pub live: Option<LiveChannel>,
}

impl<M: Serialize + std::fmt::Debug> Outlet<M> {
    /// Records `msg`, shows it live and publishes it.
    pub async fn send(&self, tap: &mut Tap, msg: M) {
        tap.output(self.channel, &msg);
        if let Some(live) = &self.live {
            live.log(&msg);
        }
        if let Err(e) = self.publisher.async_publish(msg).await {
            log::warn!("a message could not be published: {e:?}");
        }
    }
}
