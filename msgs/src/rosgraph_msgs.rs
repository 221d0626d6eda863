//! rosgraph_msgs: the simulated clock (`/clock`).

use crate::builtin_interfaces::{self, Time};
use crate::{MsgDef, RosMessage};
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

impl RosMessage for Clock {
    const DEF: &'static MsgDef = &CLOCK;
}
