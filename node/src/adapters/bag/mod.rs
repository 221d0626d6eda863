//! Recordings: rosbag2 bag directories or bare MCAP files, with rosbag2's conventions (profile
//! `ros2`, `ros2msg` schemas holding the full concatenated definition, `cdr` messages, each
//! channel's offered QoS), so that `ros2 bag`, `rosbags`, Foxglove and rerun open what the
//! twin records, and the twin replays what they record.

pub mod directory;
pub mod reader;
pub mod samples;
mod tail;
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
        let bag = write_unfinished(path);
        bag.finish().expect("finishes");
    }

    /// Ten chunks of ten levels each, flushed and not finished.
    fn write_unfinished(path: &std::path::Path) -> BagWriter {
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
        bag
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

    /// The bundled session with one bit flipped three quarters into the lz4 records of its
    /// middle chunk (where the replay test flips it). The flip decompresses into a record
    /// length of 249 GB: a reader that trusted it before the chunk's CRC aborted the process
    /// allocating it. Read, it is a damage after the whole chunks before it.
    #[test]
    fn a_flipped_bit_that_decompresses_into_a_huge_record_is_damage() {
        let session = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../tests/data/ulbra_session.mcap"
        );
        let mut bytes = std::fs::read(session).expect("the bundled session");
        let whole = BagFile::read(std::path::Path::new(session)).expect("reads");
        assert_eq!(whole.damage, None);
        let (mut chunks, mut at) = (Vec::new(), 8);
        while at + 9 <= bytes.len() {
            let len = u64::from_le_bytes(bytes[at + 1..at + 9].try_into().expect("8 bytes"));
            if bytes[at] == 0x06 {
                chunks.push((at + 9, len as usize));
            }
            at += 9 + len as usize;
        }
        let (body, len) = chunks[chunks.len() / 2];
        bytes[body + len - len / 4] ^= 0x04;
        let bad = temp("huge.mcap");
        std::fs::write(&bad, &bytes).expect("writes");
        let r = BagFile::read(&bad).expect("a damaged file is no error");
        let damage = r.damage.expect("the flip is reported");
        assert!(damage.contains("is damaged: read"), "{damage}");
        let n = r.messages.len();
        assert!(n > 0 && n < whole.messages.len(), "{n} messages");
        std::fs::remove_file(bad).ok();
    }

    /// An MCAP string: its length as a u32, then its bytes.
    fn mcap_string(s: &str) -> Vec<u8> {
        [&(s.len() as u32).to_le_bytes()[..], s.as_bytes()].concat()
    }

    /// An MCAP file's records by hand (uncompressed, no chunks): the magic, a header, then
    /// `records` as (opcode, body), then the data end.
    fn raw_mcap(records: &[(u8, Vec<u8>)]) -> Vec<u8> {
        let mut out = mcap::MAGIC.to_vec();
        let header = [mcap_string("ros2"), mcap_string("hand")].concat();
        for (op, body) in [(0x01, header)]
            .into_iter()
            .chain(records.iter().cloned())
            .chain([(0x0f, 0u32.to_le_bytes().to_vec())])
        {
            out.push(op);
            out.extend((body.len() as u64).to_le_bytes());
            out.extend(body);
        }
        out
    }

    /// A channel on a schema never declared, and a message on a channel never declared, are
    /// damage after what comes before them, as mcap's own reader has them, not skipped.
    #[test]
    fn records_that_name_what_was_never_declared_are_damage() {
        let channel = |id: u16, schema: u16| {
            let ids = [id.to_le_bytes(), schema.to_le_bytes()].concat();
            let names = [mcap_string("/gauges/p1"), mcap_string("cdr")].concat();
            (0x04, [ids, names, 0u32.to_le_bytes().to_vec()].concat())
        };
        let message = |channel: u16, seq: u32| {
            let head = [&channel.to_le_bytes()[..], &seq.to_le_bytes()].concat();
            let times = [1u64.to_le_bytes(), 1u64.to_le_bytes()].concat();
            (0x05, [head, times, vec![0, 1, 0, 0]].concat())
        };
        let cases = [
            (
                vec![channel(1, 0), message(1, 0), message(7, 1)],
                1,
                "unknown channel 7",
            ),
            (vec![channel(1, 9), message(1, 0)], 0, "unknown schema 9"),
            (vec![channel(1, 0), message(1, 0), message(1, 1)], 2, ""),
        ];
        for (k, (records, read, why)) in cases.into_iter().enumerate() {
            let path = temp(&format!("raw{k}.mcap"));
            std::fs::write(&path, raw_mcap(&records)).expect("writes");
            let r = BagFile::read(&path).expect("an MCAP file");
            assert_eq!(r.messages.len(), read, "case {k}");
            match r.damage {
                Some(d) => assert!(!why.is_empty() && d.contains(why), "case {k}: {d}"),
                None => assert!(why.is_empty(), "case {k}: no damage reported"),
            }
            std::fs::remove_file(path).ok();
        }
    }

    /// A bag directory's metadata.yaml as YAML.
    fn metadata(dir: &std::path::Path) -> serde_norway::Value {
        let text = std::fs::read_to_string(dir.join("metadata.yaml")).expect("metadata.yaml");
        let doc: serde_norway::Value = serde_norway::from_str(&text).expect("YAML");
        doc["rosbag2_bagfile_information"].clone()
    }

    #[test]
    fn a_bag_directory_holds_its_file_and_metadata_counting_each_topic() {
        let dir = temp("bag");
        write(&dir);
        let r = BagFile::read(&dir).expect("reads");
        assert_eq!(r.damage, None);
        assert_eq!(
            levels(&r),
            (0..100).map(|k| k as f64 * 1e-3).collect::<Vec<_>>()
        );
        let name = format!("flume-bag-{}-bag_0.mcap", std::process::id());
        assert!(dir.join(&name).is_file());
        let m = metadata(&dir);
        assert_eq!(m["version"], 9);
        assert_eq!(m["storage_identifier"], "mcap");
        assert_eq!(m["relative_file_paths"][0].as_str(), Some(name.as_str()));
        assert_eq!(m["files"][0]["path"].as_str(), Some(name.as_str()));
        assert_eq!(m["message_count"], 100);
        assert_eq!(m["starting_time"]["nanoseconds_since_epoch"], 0);
        assert_eq!(m["duration"]["nanoseconds"], 99_000_000_000u64);
        let topic = &m["topics_with_message_count"][0];
        assert_eq!(topic["message_count"], 100);
        assert_eq!(topic["topic_metadata"]["name"], "/gauges/p1");
        assert_eq!(topic["topic_metadata"]["type"], "flume_msgs/msg/WaterLevel");
        assert_eq!(topic["topic_metadata"]["serialization_format"], "cdr");
        let qos = &topic["topic_metadata"]["offered_qos_profiles"][0];
        assert_eq!(
            (&qos["reliability"], &qos["depth"]),
            (&"best_effort".into(), &5.into())
        );
        // rosbag2 records into a new directory only.
        let err = BagWriter::create(&dir, None).err().expect("refused");
        assert!(err.to_string().contains("is not empty"), "{err}");
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn a_recording_never_finished_reads_to_its_last_flush_with_metadata_to_match() {
        let dir = temp("killed");
        let mut bag = write_unfinished(&dir);
        // Written after the last flush, then the process dies: neither reaches the disk.
        let ch = bag
            .channel::<WaterLevel>("/gauges/p2", QOS)
            .expect("channel");
        bag.write(ch, &WaterLevel::default(), 0, 0).expect("writes");
        std::mem::forget(bag);
        let file = dir.join(format!("flume-bag-{}-killed_0.mcap", std::process::id()));
        let bytes = std::fs::read(&file).expect("reads");
        assert!(bytes.ends_with(mcap::MAGIC), "a provisional end");
        let r = BagFile::read(&dir).expect("reads");
        assert_eq!(r.damage, None);
        assert_eq!(
            levels(&r),
            (0..100).map(|k| k as f64 * 1e-3).collect::<Vec<_>>()
        );
        let m = metadata(&dir);
        assert_eq!(m["message_count"], 100);
        assert_eq!(
            m["topics_with_message_count"].as_sequence().map(Vec::len),
            Some(1)
        );
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn a_directory_that_is_no_bag_is_refused_with_the_reason() {
        let dir = temp("bad");
        std::fs::create_dir_all(&dir).expect("creates");
        let err = BagFile::read(&dir).expect_err("empty");
        assert!(
            err.to_string()
                .contains("holds no metadata.yaml and no .mcap"),
            "{err}"
        );
        let yaml = dir.join("metadata.yaml");
        std::fs::write(&yaml, "rosbag2_bagfile_information: [not, a, map").expect("writes");
        let err = format!("{:#}", BagFile::read(&dir).expect_err("corrupt"));
        assert!(err.contains("is not rosbag2 metadata"), "{err}");
        std::fs::write(
            &yaml,
            "rosbag2_bagfile_information:\n  storage_identifier: mcap\n  \
             relative_file_paths: [gone_0.mcap]\n",
        )
        .expect("writes");
        let err = BagFile::read(&dir).expect_err("missing file");
        assert!(err.to_string().contains("which is not there"), "{err}");
        std::fs::write(
            &yaml,
            "rosbag2_bagfile_information:\n  storage_identifier: sqlite3\n  \
             relative_file_paths: [bag_0.db3]\n",
        )
        .expect("writes");
        let err = BagFile::read(&dir).expect_err("sqlite3");
        assert!(err.to_string().contains("only MCAP bags"), "{err}");
        std::fs::remove_dir_all(&dir).ok();
    }
}
