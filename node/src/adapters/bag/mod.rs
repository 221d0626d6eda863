//! Recordings: MCAP files with rosbag2's conventions (profile `ros2`, `ros2msg` schemas holding
//! the full concatenated definition, `cdr` messages, each channel's offered QoS), so that
//! `ros2 bag`, Foxglove and rerun open what the twin records, and the twin replays what they
//! record.

pub mod reader;
pub mod tap;
pub mod writer;

pub use reader::{BagFile, BagMessage};
pub use writer::{BagWriter, TopicQos};

#[cfg(test)]
mod tests {
    use super::*;
    use flume_msgs::RosMessage;
    use flume_msgs::builtin_interfaces::Time;
    use flume_msgs::flume_msgs::WaterLevel;
    use flume_msgs::std_msgs::Header;

    const QOS: TopicQos = TopicQos {
        reliable: false,
        transient_local: false,
        depth: 5,
    };

    /// Ten chunks of ten levels each.
    fn write(path: &std::path::Path) {
        let mut bag = BagWriter::create(path, None).expect("creates");
        let ch = bag
            .channel::<WaterLevel>("/gauges/p1", QOS)
            .expect("channel");
        for k in 0..100u64 {
            let msg = WaterLevel {
                header: Header {
                    stamp: Time::from_secs_f64(k as f64).expect("time"),
                    frame_id: "flume".into(),
                },
                level_m: k as f64 * 1e-3,
            };
            bag.write(ch, &msg, k * 1_000_000_000, k).expect("writes");
            if k % 10 == 9 {
                bag.flush().expect("flushes");
            }
        }
        bag.finish().expect("finishes");
    }

    fn levels(r: &BagFile) -> Vec<f64> {
        r.messages
            .iter()
            .map(|m| m.decode::<WaterLevel>().expect("decodes").level_m)
            .collect()
    }

    fn temp(name: &str) -> std::path::PathBuf {
        std::env::temp_dir().join(format!("flume-bag-{}-{name}", std::process::id()))
    }

    #[test]
    fn a_recording_reads_back_with_its_schema_and_qos() {
        let path = temp("whole.mcap");
        write(&path);
        let r = BagFile::read(&path).expect("reads");
        assert_eq!(r.damage, None);
        assert_eq!(
            levels(&r),
            (0..100).map(|k| k as f64 * 1e-3).collect::<Vec<_>>()
        );
        let m = &r.messages[42];
        assert_eq!(m.topic, "/gauges/p1");
        assert_eq!(m.schema_name, "flume_msgs/msg/WaterLevel");
        assert_eq!(&*m.definition, WaterLevel::DEF.full_text().as_bytes());
        assert_eq!((m.log_ns, m.publish_ns), (42_000_000_000, 42));
        let qos = m.offered_qos_profiles.as_deref().expect("qos");
        assert!(
            qos.contains("reliability: best_effort") && qos.contains("depth: 5"),
            "{qos}"
        );
        std::fs::remove_file(&path).ok();
    }

    #[test]
    fn a_damaged_recording_gives_what_comes_before_the_damage() {
        let path = temp("good.mcap");
        write(&path);
        let bytes = std::fs::read(&path).expect("reads");
        // Cut in the middle: the chunks before the cut are whole.
        let cut = temp("cut.mcap");
        std::fs::write(&cut, &bytes[..bytes.len() / 2]).expect("writes");
        let r = BagFile::read(&cut).expect("a cut file is no error");
        let n = r.messages.len();
        assert!(
            (30..100).contains(&n) && n.is_multiple_of(10),
            "whole chunks only: {n}"
        );
        assert_eq!(
            levels(&r),
            (0..n).map(|k| k as f64 * 1e-3).collect::<Vec<_>>()
        );
        let damage = r.damage.expect("the cut is reported");
        assert!(damage.contains(&format!("read {n} messages")), "{damage}");
        // One bit flipped in the middle of the data: that chunk's CRC fails.
        let mut flipped = bytes.clone();
        flipped[bytes.len() / 2] ^= 0x10;
        let bad = temp("flipped.mcap");
        std::fs::write(&bad, &flipped).expect("writes");
        let r = BagFile::read(&bad).expect("a damaged file is no error");
        let m = r.messages.len();
        assert!((30..100).contains(&m), "{m}");
        assert_eq!(
            levels(&r),
            (0..m).map(|k| k as f64 * 1e-3).collect::<Vec<_>>()
        );
        assert!(r.damage.is_some());
        // Not a recording at all.
        let junk = temp("junk.mcap");
        std::fs::write(&junk, b"not a recording").expect("writes");
        let err = BagFile::read(&junk).expect_err("refused");
        assert!(
            err.to_string().contains("is not an MCAP recording"),
            "{err}"
        );
        for p in [path, cut, bad, junk] {
            std::fs::remove_file(p).ok();
        }
    }
}
