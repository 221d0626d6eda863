//! std_msgs: the header every stamped message starts with, and colours.

use crate::MsgDef;
use crate::builtin_interfaces::{self, Time};
use serde::{Deserialize, Serialize};

#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Header {
    pub stamp: Time,
    pub frame_id: String,
}

/// A colour, each component 0..1.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct ColorRGBA {
    pub r: f32,
    pub g: f32,
    pub b: f32,
    pub a: f32,
}

pub static HEADER: MsgDef = MsgDef {
    package: "std_msgs",
    name: "Header",
    text: "builtin_interfaces/Time stamp\nstring frame_id\n",
    uses: &[&builtin_interfaces::TIME],
};

pub static COLOR_RGBA: MsgDef = MsgDef {
    package: "std_msgs",
    name: "ColorRGBA",
    text: "float32 r\nfloat32 g\nfloat32 b\nfloat32 a\n",
    uses: &[],
};

crate::ros_message!(Header, HEADER);

crate::ros_message!(ColorRGBA, COLOR_RGBA);
