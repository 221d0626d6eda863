//! builtin_interfaces: time stamps and durations.

use crate::MsgDef;
use serde::{Deserialize, Serialize};

/// A point in time: seconds and nanoseconds (0 <= nanosec < 1e9).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, PartialOrd, Ord, Serialize, Deserialize)]
pub struct Time {
    pub sec: i32,
    pub nanosec: u32,
}

/// A span of time: seconds and nanoseconds (0 <= nanosec < 1e9).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Duration {
    pub sec: i32,
    pub nanosec: u32,
}

pub static TIME: MsgDef = MsgDef {
    package: "builtin_interfaces",
    name: "Time",
    text: "int32 sec\nuint32 nanosec\n",
    uses: &[],
};

pub static DURATION: MsgDef = MsgDef {
    package: "builtin_interfaces",
    name: "Duration",
    text: "int32 sec\nuint32 nanosec\n",
    uses: &[],
};

crate::ros_message!(Time, TIME);

crate::ros_message!(Duration, DURATION);

impl Time {
    /// The time `t_s` seconds after the epoch; None outside the i32 seconds range or when not
    /// finite.
    pub fn from_secs_f64(t_s: f64) -> Option<Time> {
        if !t_s.is_finite() {
            return None;
        }
        let sec = t_s.floor();
        if sec < f64::from(i32::MIN) || sec > f64::from(i32::MAX) {
            return None;
        }
        // Rounding can carry the nanoseconds up to a whole second.
        let nanosec = (((t_s - sec) * 1e9).round() as u32).min(999_999_999);
        Some(Time {
            sec: sec as i32,
            nanosec,
        })
    }

    /// Seconds since the epoch.
    pub fn as_secs_f64(self) -> f64 {
        f64::from(self.sec) + f64::from(self.nanosec) * 1e-9
    }

    /// Nanoseconds since the epoch (MCAP's log and publish times); None before the epoch.
    pub fn as_nanos(self) -> Option<u64> {
        u64::try_from(self.sec)
            .ok()
            .map(|s| s * 1_000_000_000 + u64::from(self.nanosec))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn seconds_convert_both_ways() {
        let t = Time::from_secs_f64(12.25).expect("in range");
        assert_eq!(
            t,
            Time {
                sec: 12,
                nanosec: 250_000_000
            }
        );
        assert_eq!(t.as_secs_f64(), 12.25);
        assert_eq!(t.as_nanos(), Some(12_250_000_000));
        // -1.7 s is sec -2 plus 0.3 s, as builtin_interfaces defines it.
        let t = Time::from_secs_f64(-1.7).expect("in range");
        assert_eq!((t.sec, t.nanosec), (-2, 300_000_000));
        assert_eq!(t.as_nanos(), None);
        assert_eq!(Time::from_secs_f64(f64::NAN), None);
        assert_eq!(Time::from_secs_f64(3e9), None);
    }
}
