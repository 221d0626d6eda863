//! flume-msgs: the ROS 2 messages flume-twin reads and writes, as Rust structs whose serde
//! form is ROS 2's CDR (field order and widths as in the `.msg` definitions), and the
//! definitions themselves, for a recorder that must store them (rosbag2 / MCAP).
//!
//! `msg/*.msg` with `package.xml` and `CMakeLists.txt` make the ROS package `flume_msgs`, so
//! rclpy and rviz users can build and decode our own types. The standard types used by the
//! node (std_msgs, builtin_interfaces, geometry_msgs, sensor_msgs, visualization_msgs,
//! rosgraph_msgs, diagnostic_msgs) are mirrored here field for field from their Jazzy
//! definitions; their texts here keep the fields and constants and leave out the comments.

pub mod builtin_interfaces;
pub mod definition;
pub mod diagnostic_msgs;
pub mod flume_msgs;
pub mod geometry_msgs;
pub mod rosgraph_msgs;
pub mod sensor_msgs;
pub mod std_msgs;
pub mod std_srvs;
pub mod visualization_msgs;

pub use definition::{MsgDef, RosMessage};
