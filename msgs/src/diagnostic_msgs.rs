//! diagnostic_msgs: what `/diagnostics` carries.

use crate::MsgDef;
use crate::std_msgs::{self, Header};
use serde::{Deserialize, Serialize};

#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct KeyValue {
    pub key: String,
    pub value: String,
}

#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct DiagnosticStatus {
    /// One of the level constants below.
    pub level: u8,
    pub name: String,
    pub message: String,
    pub hardware_id: String,
    pub values: Vec<KeyValue>,
}

impl DiagnosticStatus {
    pub const OK: u8 = 0;
    pub const WARN: u8 = 1;
    pub const ERROR: u8 = 2;
    pub const STALE: u8 = 3;
}

#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct DiagnosticArray {
    pub header: Header,
    pub status: Vec<DiagnosticStatus>,
}

pub static KEY_VALUE: MsgDef = MsgDef {
    package: "diagnostic_msgs",
    name: "KeyValue",
    text: "string key\nstring value\n",
    uses: &[],
};

pub static DIAGNOSTIC_STATUS: MsgDef = MsgDef {
    package: "diagnostic_msgs",
    name: "DiagnosticStatus",
    text: "byte OK=0\nbyte WARN=1\nbyte ERROR=2\nbyte STALE=3\nbyte level\nstring name\nstring message\nstring hardware_id\ndiagnostic_msgs/KeyValue[] values\n",
    uses: &[&KEY_VALUE],
};

pub static DIAGNOSTIC_ARRAY: MsgDef = MsgDef {
    package: "diagnostic_msgs",
    name: "DiagnosticArray",
    text: "std_msgs/Header header\ndiagnostic_msgs/DiagnosticStatus[] status\n",
    uses: &[&std_msgs::HEADER, &DIAGNOSTIC_STATUS],
};

crate::ros_message!(KeyValue, KEY_VALUE);

crate::ros_message!(DiagnosticStatus, DIAGNOSTIC_STATUS);

crate::ros_message!(DiagnosticArray, DIAGNOSTIC_ARRAY);
