//! The twin's topics: names relative to the node's namespace, and the QoS each is offered or
//! requested with (DESIGN.md's table). The node, the recorder and the session generator all
//! read them here, so a recording says what the wire did.

use crate::adapters::bag::TopicQos;

pub const INFLOW: &str = "inflow";
/// A gauge's topic is `gauges/<name>`, the name in lower case.
pub fn gauge(name: &str) -> String {
    format!("gauges/{}", name.to_lowercase())
}
pub const BED_PROFILE: &str = "bed_profile";
pub const ERODED_MASS: &str = "eroded_mass";
pub const GAUGE_COMPARISON: &str = "gauges/predicted";
pub const PARTICLES: &str = "particles";
pub const BED_MARKER: &str = "bed_marker";
pub const CLOCK: &str = "/clock";
pub const DIAGNOSTICS: &str = "/diagnostics";

pub const INFLOW_QOS: TopicQos = reliable(10);
/// ROS's sensor-data profile.
pub const GAUGE_QOS: TopicQos = TopicQos {
    reliable: false,
    transient_local: false,
    depth: 5,
};
/// A late joiner gets the latest bed.
pub const LATCHED_QOS: TopicQos = TopicQos {
    reliable: true,
    transient_local: true,
    depth: 1,
};
pub const OUTPUT_QOS: TopicQos = reliable(10);
/// Only the newest matters, and a lost one is replaced within the period.
pub const STREAM_QOS: TopicQos = TopicQos {
    reliable: false,
    transient_local: false,
    depth: 1,
};

const fn reliable(depth: usize) -> TopicQos {
    TopicQos {
        reliable: true,
        transient_local: false,
        depth,
    }
}
