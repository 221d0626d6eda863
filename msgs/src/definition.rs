//! Message definitions and their concatenation as rosbag2 stores it: the type's own text, then
//! each type it uses (depth first, each once) after a line of 80 `=` and `MSG: pkg/Type`.

/// One message type: its package, name, `.msg` text, and the message types its fields use.
#[derive(Debug)]
pub struct MsgDef {
    pub package: &'static str,
    pub name: &'static str,
    pub text: &'static str,
    pub uses: &'static [&'static MsgDef],
}

impl MsgDef {
    /// `pkg/msg/Type`, the schema name of MCAP's ros2msg encoding.
    pub fn schema_name(&self) -> String {
        format!("{}/msg/{}", self.package, self.name)
    }

    /// The definition with every type it uses, as rosbag2 writes it.
    pub fn full_text(&self) -> String {
        let mut out = self.text.trim_end().to_string();
        let mut seen: Vec<*const MsgDef> = vec![self];
        let mut stack: Vec<&MsgDef> = self.uses.iter().rev().copied().collect();
        while let Some(def) = stack.pop() {
            if seen.contains(&(def as *const MsgDef)) {
                continue;
            }
            seen.push(def);
            out.push('\n');
            out.push_str(&"=".repeat(80));
            out.push_str(&format!("\nMSG: {}/{}\n", def.package, def.name));
            out.push_str(def.text.trim_end());
            stack.extend(def.uses.iter().rev().copied());
        }
        out.push('\n');
        out
    }
}

/// A Rust mirror of a ROS 2 message type.
pub trait RosMessage {
    const DEF: &'static MsgDef;
}

/// Declares a type the mirror of the ROS 2 type `def`, for us and for ros2-client.
#[macro_export]
macro_rules! ros_message {
    ($t:ty, $def:expr) => {
        impl $crate::RosMessage for $t {
            const DEF: &'static $crate::MsgDef = &$def;
        }
        impl ros2_client::Message for $t {}
    };
}

#[cfg(test)]
mod tests {
    use super::*;

    static LEAF: MsgDef = MsgDef {
        package: "p",
        name: "Leaf",
        text: "int32 a\n",
        uses: &[],
    };
    static MID: MsgDef = MsgDef {
        package: "p",
        name: "Mid",
        text: "p/Leaf leaf\n",
        uses: &[&LEAF],
    };
    static TOP: MsgDef = MsgDef {
        package: "q",
        name: "Top",
        text: "p/Mid mid\np/Leaf other\n",
        uses: &[&MID, &LEAF],
    };

    #[test]
    fn dependencies_follow_depth_first_each_once() {
        let bar = "=".repeat(80);
        assert_eq!(
            TOP.full_text(),
            format!(
                "p/Mid mid\np/Leaf other\n{bar}\nMSG: p/Mid\np/Leaf leaf\n{bar}\nMSG: p/Leaf\nint32 a\n"
            )
        );
        assert_eq!(TOP.schema_name(), "q/msg/Top");
    }
}
