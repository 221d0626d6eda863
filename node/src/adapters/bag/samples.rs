//! Samples of the sensors from a recording: which topic is which sensor, and the message as the
//! twin takes it (`twin::samples`).

use super::BagMessage;
use crate::adapters::topics;
use crate::twin::samples::Sample;
use anyhow::Result;
use flume_msgs::RosMessage;
use flume_msgs::flume_msgs::{Discharge, WaterLevel};
use flume_msgs::sensor_msgs::Range;

/// What a recorded topic is to the twin: the inflow (`Some(None)`), gauge `k`
/// (`Some(Some(k))`), or nothing. A topic matches by its last segments (`.../inflow`,
/// `.../gauges/p1`) whatever namespace it was recorded in, and by its type.
pub fn role(msg: &BagMessage, gauges: &[String]) -> Option<Option<usize>> {
    let ends =
        |name: &str| msg.topic == format!("/{name}") || msg.topic.ends_with(&format!("/{name}"));
    if msg.schema_name == Discharge::DEF.schema_name() && ends(topics::INFLOW) {
        return Some(None);
    }
    let gauge_type = msg.schema_name == WaterLevel::DEF.schema_name()
        || msg.schema_name == Range::DEF.schema_name();
    gauges
        .iter()
        .position(|g| gauge_type && ends(&topics::gauge(g)))
        .map(Some)
}

/// Decodes a recorded sample of the role `role` (see [`role`]).
pub fn decode(msg: &BagMessage, role: Option<usize>) -> Result<Sample> {
    Ok(match role {
        None => Sample::Inflow(msg.decode()?),
        Some(k) if msg.schema_name == Range::DEF.schema_name() => Sample::Range(k, msg.decode()?),
        Some(k) => Sample::Level(k, msg.decode()?),
    })
}
