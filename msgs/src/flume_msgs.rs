//! flume_msgs: the twin's own types. Their definitions are the ROS package's `msg/*.msg` files.

use crate::MsgDef;
use crate::std_msgs::{self, Header};
use serde::{Deserialize, Serialize};

/// Inflow discharge from the flume's flow meter.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Discharge {
    pub header: Header,
    /// m3/s.
    pub discharge_m3_per_s: f64,
}

/// Water level at one gauge, above the flume floor.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct WaterLevel {
    pub header: Header,
    /// m.
    pub level_m: f64,
}

/// The bed along the flume: Zb, Zs, Zw per column (NaN where absent), m.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct BedProfile {
    pub header: Header,
    pub x_m: Vec<f64>,
    pub zb_m: Vec<f64>,
    pub zs_m: Vec<f64>,
    pub zw_m: Vec<f64>,
}

/// Eroded sediment (Eq. 34) since the start, with the mass worn off the bed as bed load under
/// `van_rijn_exner` (`ErodedMass.msg`).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct ErodedMass {
    pub header: Header,
    pub eroded_kg_per_m: f64,
    pub eroded_kg: f64,
    pub rate_kg_per_s: f64,
    pub particles: u64,
}

/// One gauge: prediction against measurement, m (NaN where missing).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct GaugeResidual {
    pub name: String,
    pub predicted_m: f64,
    pub measured_m: f64,
    pub residual_m: f64,
    pub stale: bool,
}

#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct GaugeComparison {
    pub header: Header,
    pub gauges: Vec<GaugeResidual>,
}

pub static DISCHARGE: MsgDef = MsgDef {
    package: "flume_msgs",
    name: "Discharge",
    text: include_str!("../msg/Discharge.msg"),
    uses: &[&std_msgs::HEADER],
};

pub static WATER_LEVEL: MsgDef = MsgDef {
    package: "flume_msgs",
    name: "WaterLevel",
    text: include_str!("../msg/WaterLevel.msg"),
    uses: &[&std_msgs::HEADER],
};

pub static BED_PROFILE: MsgDef = MsgDef {
    package: "flume_msgs",
    name: "BedProfile",
    text: include_str!("../msg/BedProfile.msg"),
    uses: &[&std_msgs::HEADER],
};

pub static ERODED_MASS: MsgDef = MsgDef {
    package: "flume_msgs",
    name: "ErodedMass",
    text: include_str!("../msg/ErodedMass.msg"),
    uses: &[&std_msgs::HEADER],
};

pub static GAUGE_RESIDUAL: MsgDef = MsgDef {
    package: "flume_msgs",
    name: "GaugeResidual",
    text: include_str!("../msg/GaugeResidual.msg"),
    uses: &[],
};

pub static GAUGE_COMPARISON: MsgDef = MsgDef {
    package: "flume_msgs",
    name: "GaugeComparison",
    text: include_str!("../msg/GaugeComparison.msg"),
    uses: &[&std_msgs::HEADER, &GAUGE_RESIDUAL],
};

crate::ros_message!(Discharge, DISCHARGE);

crate::ros_message!(WaterLevel, WATER_LEVEL);

crate::ros_message!(BedProfile, BED_PROFILE);

crate::ros_message!(ErodedMass, ERODED_MASS);

crate::ros_message!(GaugeResidual, GAUGE_RESIDUAL);

crate::ros_message!(GaugeComparison, GAUGE_COMPARISON);
