//! sensor_msgs: ultrasonic gauges (`Range`), particle clouds (`PointCloud2`), and the image a
//! marker may carry.

use crate::MsgDef;
use crate::std_msgs::{self, Header};
use serde::{Deserialize, Serialize};

/// A distance reading; a flume gauge's water level is its mount height minus `range`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Range {
    pub header: Header,
    /// ULTRASOUND or INFRARED.
    pub radiation_type: u8,
    /// rad.
    pub field_of_view: f32,
    /// m.
    pub min_range: f32,
    /// m.
    pub max_range: f32,
    /// m.
    pub range: f32,
    /// m2; 0 when unknown.
    pub variance: f32,
}

impl Range {
    pub const ULTRASOUND: u8 = 0;
    pub const INFRARED: u8 = 1;
}

/// One field of a point in a `PointCloud2`'s `data`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct PointField {
    pub name: String,
    /// Bytes from the start of the point.
    pub offset: u32,
    /// One of the datatype constants below.
    pub datatype: u8,
    pub count: u32,
}

impl PointField {
    pub const INT8: u8 = 1;
    pub const UINT8: u8 = 2;
    pub const INT16: u8 = 3;
    pub const UINT16: u8 = 4;
    pub const INT32: u8 = 5;
    pub const UINT32: u8 = 6;
    pub const FLOAT32: u8 = 7;
    pub const FLOAT64: u8 = 8;
}

#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct PointCloud2 {
    pub header: Header,
    pub height: u32,
    pub width: u32,
    pub fields: Vec<PointField>,
    pub is_bigendian: bool,
    /// Bytes per point.
    pub point_step: u32,
    /// Bytes per row.
    pub row_step: u32,
    #[serde(with = "serde_bytes")]
    pub data: Vec<u8>,
    pub is_dense: bool,
}

#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct CompressedImage {
    pub header: Header,
    pub format: String,
    #[serde(with = "serde_bytes")]
    pub data: Vec<u8>,
}

pub static RANGE: MsgDef = MsgDef {
    package: "sensor_msgs",
    name: "Range",
    text: "std_msgs/Header header\nuint8 ULTRASOUND=0\nuint8 INFRARED=1\nuint8 radiation_type\nfloat32 field_of_view\nfloat32 min_range\nfloat32 max_range\nfloat32 range\nfloat32 variance\n",
    uses: &[&std_msgs::HEADER],
};

pub static POINT_FIELD: MsgDef = MsgDef {
    package: "sensor_msgs",
    name: "PointField",
    text: "uint8 INT8=1\nuint8 UINT8=2\nuint8 INT16=3\nuint8 UINT16=4\nuint8 INT32=5\nuint8 UINT32=6\nuint8 FLOAT32=7\nuint8 FLOAT64=8\nstring name\nuint32 offset\nuint8 datatype\nuint32 count\n",
    uses: &[],
};

pub static POINT_CLOUD2: MsgDef = MsgDef {
    package: "sensor_msgs",
    name: "PointCloud2",
    text: "std_msgs/Header header\nuint32 height\nuint32 width\nsensor_msgs/PointField[] fields\nbool is_bigendian\nuint32 point_step\nuint32 row_step\nuint8[] data\nbool is_dense\n",
    uses: &[&std_msgs::HEADER, &POINT_FIELD],
};

pub static COMPRESSED_IMAGE: MsgDef = MsgDef {
    package: "sensor_msgs",
    name: "CompressedImage",
    text: "std_msgs/Header header\nstring format\nuint8[] data\n",
    uses: &[&std_msgs::HEADER],
};

crate::ros_message!(Range, RANGE);

crate::ros_message!(PointField, POINT_FIELD);

crate::ros_message!(PointCloud2, POINT_CLOUD2);

crate::ros_message!(CompressedImage, COMPRESSED_IMAGE);
