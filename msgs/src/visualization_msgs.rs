//! visualization_msgs: the markers rviz draws (the bed and water lines).

use crate::MsgDef;
use crate::builtin_interfaces::{self, Duration};
use crate::geometry_msgs::{self, Point, Pose, Vector3};
use crate::sensor_msgs::{self, CompressedImage};
use crate::std_msgs::{self, ColorRGBA, Header};
use serde::{Deserialize, Serialize};

#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct UVCoordinate {
    pub u: f32,
    pub v: f32,
}

#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct MeshFile {
    pub filename: String,
    #[serde(with = "serde_bytes")]
    pub data: Vec<u8>,
}

#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Marker {
    pub header: Header,
    pub ns: String,
    pub id: i32,
    /// One of the shape constants below.
    #[serde(rename = "type")]
    pub kind: i32,
    /// ADD, DELETE or DELETEALL.
    pub action: i32,
    pub pose: Pose,
    pub scale: Vector3,
    pub color: ColorRGBA,
    pub lifetime: Duration,
    pub frame_locked: bool,
    pub points: Vec<Point>,
    pub colors: Vec<ColorRGBA>,
    pub texture_resource: String,
    pub texture: CompressedImage,
    pub uv_coordinates: Vec<UVCoordinate>,
    pub text: String,
    pub mesh_resource: String,
    pub mesh_file: MeshFile,
    pub mesh_use_embedded_materials: bool,
}

impl Marker {
    pub const ARROW: i32 = 0;
    pub const CUBE: i32 = 1;
    pub const SPHERE: i32 = 2;
    pub const CYLINDER: i32 = 3;
    pub const LINE_STRIP: i32 = 4;
    pub const LINE_LIST: i32 = 5;
    pub const CUBE_LIST: i32 = 6;
    pub const SPHERE_LIST: i32 = 7;
    pub const POINTS: i32 = 8;
    pub const TEXT_VIEW_FACING: i32 = 9;
    pub const MESH_RESOURCE: i32 = 10;
    pub const TRIANGLE_LIST: i32 = 11;
    pub const ARROW_STRIP: i32 = 12;
    pub const ADD: i32 = 0;
    pub const MODIFY: i32 = 0;
    pub const DELETE: i32 = 2;
    pub const DELETEALL: i32 = 3;
}

#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct MarkerArray {
    pub markers: Vec<Marker>,
}

pub static UV_COORDINATE: MsgDef = MsgDef {
    package: "visualization_msgs",
    name: "UVCoordinate",
    text: "float32 u\nfloat32 v\n",
    uses: &[],
};

pub static MESH_FILE: MsgDef = MsgDef {
    package: "visualization_msgs",
    name: "MeshFile",
    text: "string filename\nuint8[] data\n",
    uses: &[],
};

pub static MARKER: MsgDef = MsgDef {
    package: "visualization_msgs",
    name: "Marker",
    text: "int32 ARROW=0\nint32 CUBE=1\nint32 SPHERE=2\nint32 CYLINDER=3\nint32 LINE_STRIP=4\n\
int32 LINE_LIST=5\nint32 CUBE_LIST=6\nint32 SPHERE_LIST=7\nint32 POINTS=8\n\
int32 TEXT_VIEW_FACING=9\nint32 MESH_RESOURCE=10\nint32 TRIANGLE_LIST=11\nint32 ARROW_STRIP=12\n\
int32 ADD=0\nint32 MODIFY=0\nint32 DELETE=2\nint32 DELETEALL=3\n\
std_msgs/Header header\nstring ns\nint32 id\nint32 type\nint32 action\n\
geometry_msgs/Pose pose\ngeometry_msgs/Vector3 scale\nstd_msgs/ColorRGBA color\n\
builtin_interfaces/Duration lifetime\nbool frame_locked\ngeometry_msgs/Point[] points\n\
std_msgs/ColorRGBA[] colors\nstring texture_resource\nsensor_msgs/CompressedImage texture\n\
visualization_msgs/UVCoordinate[] uv_coordinates\nstring text\nstring mesh_resource\n\
visualization_msgs/MeshFile mesh_file\nbool mesh_use_embedded_materials\n",
    uses: &[
        &std_msgs::HEADER,
        &geometry_msgs::POSE,
        &geometry_msgs::VECTOR3,
        &std_msgs::COLOR_RGBA,
        &builtin_interfaces::DURATION,
        &geometry_msgs::POINT,
        &sensor_msgs::COMPRESSED_IMAGE,
        &UV_COORDINATE,
        &MESH_FILE,
    ],
};

pub static MARKER_ARRAY: MsgDef = MsgDef {
    package: "visualization_msgs",
    name: "MarkerArray",
    text: "visualization_msgs/Marker[] markers\n",
    uses: &[&MARKER],
};

crate::ros_message!(UVCoordinate, UV_COORDINATE);

crate::ros_message!(MeshFile, MESH_FILE);

crate::ros_message!(Marker, MARKER);

crate::ros_message!(MarkerArray, MARKER_ARRAY);
