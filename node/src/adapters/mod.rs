//! Where the twin meets the world: ROS 2 over DDS, iceoryx2 particle frames, MCAP bags, the
//! Foxglove live view, the files and terminal tables of the offline commands.

pub mod bag;
pub mod files;
pub mod foxglove;
pub mod frames;
pub mod progress;
pub mod ros;
pub mod table;
pub mod topics;
