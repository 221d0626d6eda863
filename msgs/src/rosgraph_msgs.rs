//! rosgraph_msgs: the simulated clock (`/clock`).

use crate::MsgDef;
use crate::builtin_interfaces::{self, Time};
use serde::{Deserialize, Serialize};

#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Clock {
    pub clock: Time,
}

pub static CLOCK: MsgDef = MsgDef {
    package: "rosgraph_msgs",
    name: "Clock",
    text: "builtin_interfaces/Time clock\n",
    uses: &[&builtin_interfaces::TIME],
};

crate::ros_message!(Clock, CLOCK);
