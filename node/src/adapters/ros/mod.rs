//! ROS 2 over DDS (ros2-client): the participant, topic names after the remaps, QoS, the
//! publishers the twin records through its tap; the node's parameters and services are in
//! [`parameters`] and [`services`].

pub mod args;
pub mod parameters;
pub mod services;

use crate::adapters::bag::TopicQos;
use crate::adapters::bag::tap::{Outlet, Tap};
use crate::adapters::foxglove::LiveView;
use anyhow::{Context as _, Result, anyhow};
use args::RosArgs;
use flume_msgs::{MsgDef, RosMessage};
use ros2_client::dds::rustdds::DomainParticipantBuilder;
use ros2_client::qos::{Durability, History, WhenFull};
use ros2_client::{Context, MessageTypeName, Name, Node, QosProfile, Subscription};
use serde::Serialize;
use serde::de::DeserializeOwned;
use std::net::Ipv4Addr;

/// A topic's QoS as ros2-client takes it.
pub fn qos(t: TopicQos) -> QosProfile {
    let q = QosProfile::publisher_default()
        .durability(if t.transient_local {
            Durability::TransientLocal
        } else {
            Durability::Volatile
        })
        .history(History::KeepLast { depth: t.depth });
    if t.reliable {
        q.reliability_reliable(WhenFull::DEFAULT)
    } else {
        q.reliability_best_effort()
    }
}

pub fn type_name(def: &MsgDef) -> MessageTypeName {
    MessageTypeName::new(def.package, def.name)
}

/// A full topic name (`/ns/name`) as ros2-client takes it. Names go to ros2-client absolute:
/// a relative one under the root namespace would reach DDS as `rt//name`, which no other ROS
/// node uses.
pub fn topic_name(full: &str) -> Result<Name> {
    Name::parse(full).map_err(|e| anyhow!("topic {full:?}: {e}"))
}

/// A topic's full name after the remaps, as the wire and a recording name it.
pub fn full_topic(namespace: &str, ros: &RosArgs, name: &str) -> String {
    let remapped = ros.remap(name);
    if remapped.starts_with('/') {
        remapped
    } else {
        format!("{}/{remapped}", namespace.trim_end_matches('/'))
    }
}

/// A publisher of `M` on `name`, recorded when the node records, shown when it serves
/// Foxglove.
pub fn outlet<M: RosMessage + Serialize>(
    node: &mut Node,
    recorder: &mut Tap,
    view: &LiveView,
    full: &dyn Fn(&str) -> String,
    name: &str,
    topic_qos: TopicQos,
) -> Result<Outlet<M>> {
    let q = qos(topic_qos);
    let topic = node
        .create_topic(&topic_name(&full(name))?, type_name(M::DEF), &q)
        .with_context(|| format!("cannot create topic {name}"))?;
    Ok(Outlet {
        publisher: node
            .create_publisher::<M>(&topic, Some(q))
            .with_context(|| format!("cannot publish {name}"))?,
        channel: recorder.channel::<M>(&full(name), topic_qos)?,
        live: view.channel::<M>(&full(name))?,
    })
}

pub fn subscription<M: RosMessage + DeserializeOwned + 'static>(
    node: &mut Node,
    full: &dyn Fn(&str) -> String,
    name: &str,
    qos: QosProfile,
) -> Result<Subscription<M>> {
    let topic = node
        .create_topic(&topic_name(&full(name))?, type_name(M::DEF), &qos)
        .with_context(|| format!("cannot create topic {name}"))?;
    node.create_subscription::<M>(&topic, Some(qos))
        .with_context(|| format!("cannot subscribe to {name}"))
}

/// ROS 2 on DDS domain `domain_id`, on the loopback interface only when `loopback`.
pub fn dds_context(loopback: bool, domain_id: u16) -> Result<Context> {
    if loopback {
        let participant = DomainParticipantBuilder::new(domain_id)
            .with_only_networks([Ipv4Addr::LOCALHOST])
            .build()
            .context("cannot start DDS on the loopback interface")?;
        Context::from_domain_participant(participant)
    } else {
        Context::with_options(ros2_client::ContextOptions::new().domain_id(domain_id))
    }
    .context("cannot start ROS 2 (DDS)")
}
