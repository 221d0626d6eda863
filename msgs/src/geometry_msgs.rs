//! geometry_msgs: the points, orientations and vectors a marker is made of.

use crate::MsgDef;
use serde::{Deserialize, Serialize};

#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Point {
    pub x: f64,
    pub y: f64,
    pub z: f64,
}

#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Quaternion {
    pub x: f64,
    pub y: f64,
    pub z: f64,
    pub w: f64,
}

/// The identity rotation, the definition's default.
impl Default for Quaternion {
    fn default() -> Self {
        Quaternion {
            x: 0.0,
            y: 0.0,
            z: 0.0,
            w: 1.0,
        }
    }
}

#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Pose {
    pub position: Point,
    pub orientation: Quaternion,
}

#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Vector3 {
    pub x: f64,
    pub y: f64,
    pub z: f64,
}

pub static POINT: MsgDef = MsgDef {
    package: "geometry_msgs",
    name: "Point",
    text: "float64 x\nfloat64 y\nfloat64 z\n",
    uses: &[],
};

pub static QUATERNION: MsgDef = MsgDef {
    package: "geometry_msgs",
    name: "Quaternion",
    text: "float64 x 0\nfloat64 y 0\nfloat64 z 0\nfloat64 w 1\n",
    uses: &[],
};

pub static POSE: MsgDef = MsgDef {
    package: "geometry_msgs",
    name: "Pose",
    text: "geometry_msgs/Point position\ngeometry_msgs/Quaternion orientation\n",
    uses: &[&POINT, &QUATERNION],
};

pub static VECTOR3: MsgDef = MsgDef {
    package: "geometry_msgs",
    name: "Vector3",
    text: "float64 x\nfloat64 y\nfloat64 z\n",
    uses: &[],
};

crate::ros_message!(Point, POINT);

crate::ros_message!(Quaternion, QUATERNION);

crate::ros_message!(Pose, POSE);

crate::ros_message!(Vector3, VECTOR3);
