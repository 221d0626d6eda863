//! std_srvs/srv/Trigger: the twin's reset, pause, resume and step services.

use serde::{Deserialize, Serialize};

/// An empty request: ROS 2 gives an empty structure one byte.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct TriggerRequest {
    pub structure_needs_at_least_one_member: u8,
}

#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct TriggerResponse {
    pub success: bool,
    pub message: String,
}

impl ros2_client::Message for TriggerRequest {}
impl ros2_client::Message for TriggerResponse {}
