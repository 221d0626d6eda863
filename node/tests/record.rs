//! The node's recording (`run --record DIR`), with the bundled session playing the sensors (no
//! sensor is on the network): a rosbag2 bag directory. SIGTERM finishes it, and two readers
//! written elsewhere read it whole: Python `mcap` + `mcap-ros2-support` its MCAP file, every
//! input and output topic with its schema, and `rosbags` the directory through its
//! metadata.yaml, with the same counts, the session's own gauge levels and discharges, and the
//! same predictions. `kill -9` leaves a bag that both, and the twin's replay, read up to the
//! last flushed chunk. A directory that is no bag is refused with the reason.

mod common;

use common::{ULBRA_CI, gpu, interop_json, printed, python_has, read_mcap, repo_file, ulbra_twin};
use serde_json::Value;
use std::collections::BTreeMap;
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// Starts the twin at CI size in the repository's root, so the bundled session is found where
/// the README's command finds it.
fn start(record: &Path) -> Child {
    ulbra_twin()
        .args([
            "--silent-wait-s",
            "0.5",
            "--record",
            record.to_str().expect("utf-8"),
            "--ros-args",
            "-r",
            &format!("__ns:={}", ns()),
        ])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("starts the twin")
}

/// The twin's namespace: its own, so no other test's traffic mixes in.
fn ns() -> String {
    format!("/flume_record_{}", std::process::id())
}

/// Waits until `path` holds at least `bytes` (the recorder has flushed some chunks).
fn wait_for(path: &Path, bytes: u64) {
    let started = Instant::now();
    while std::fs::metadata(path).map_or(0, |m| m.len()) < bytes {
        assert!(
            started.elapsed() < Duration::from_secs(180),
            "{} never reached {bytes} bytes",
            path.display()
        );
        std::thread::sleep(Duration::from_millis(200));
    }
}

/// Messages on `topic`, relative to the twin's namespace unless absolute.
fn count(got: &Value, topic: &str) -> u64 {
    got["channels"][full(topic)]["count"].as_u64().unwrap_or(0)
}

fn full(topic: &str) -> String {
    if topic.starts_with('/') {
        topic.to_string()
    } else {
        format!("{}/{topic}", ns())
    }
}

/// The bag directory `dir` as `rosbags` reads it (`tests/interop/read_rosbag.py`), with the
/// messages of `topics` decoded.
fn read_rosbag(dir: &Path, topics: &[String]) -> Value {
    interop_json("read_rosbag.py", dir, topics)
}

/// The bag's MCAP file.
fn mcap_in(dir: &Path) -> std::path::PathBuf {
    let name = dir.file_name().and_then(|n| n.to_str()).expect("a name");
    dir.join(format!("{name}_0.mcap"))
}

/// `field` of each decoded message on `topic`, in order.
fn values(got: &Value, topic: &str, field: impl Fn(&Value) -> Value) -> Vec<Value> {
    got["messages"]
        .as_array()
        .expect("messages")
        .iter()
        .filter(|m| m["topic"] == topic)
        .map(|m| field(&m["msg"]))
        .collect()
}

/// Per topic, the messages `rosbags` read, and what its metadata.yaml says it holds.
fn rosbags_counts(got: &Value) -> BTreeMap<String, (u64, u64)> {
    got["topics"]
        .as_object()
        .expect("topics")
        .iter()
        .map(|(t, v)| {
            let n = |k: &str| v[k].as_u64().expect("a count");
            (t.clone(), (n("read"), n("metadata_count")))
        })
        .collect()
}

/// What `rosbags` reads of the bag `dir` against what Python's `mcap` reads of its file
/// (`mcap`): the same topics and counts, metadata counts no larger (equal when `finished`),
/// the same decoded levels, discharges and predictions, and the levels and discharges the
/// session played, in its order.
fn rosbags_agrees(dir: &Path, mcap: &Value, finished: bool) {
    let (p1, inflow, predicted) = (full("gauges/p1"), full("inflow"), full("gauges/predicted"));
    let got = read_rosbag(dir, &[p1.clone(), inflow.clone(), predicted.clone()]);
    assert!(got["error"].is_null(), "rosbags: {}", got["error"]);
    let counts = rosbags_counts(&got);
    let theirs: BTreeMap<String, u64> = mcap["channels"]
        .as_object()
        .expect("channels")
        .iter()
        .map(|(t, c)| (t.clone(), c["count"].as_u64().expect("count")))
        .collect();
    // A topic with no message yet has no channel count in mcap's reading.
    let read: BTreeMap<String, u64> = counts
        .iter()
        .filter(|(_, c)| c.0 > 0)
        .map(|(t, c)| (t.clone(), c.0))
        .collect();
    assert_eq!(read, theirs, "rosbags and mcap count alike");
    for (topic, (read, listed)) in &counts {
        if finished {
            assert_eq!(read, listed, "{topic}: metadata.yaml counts what is there");
        } else {
            // The metadata is written after each flush: at most one flush behind.
            assert!(listed <= read, "{topic}: {listed} listed, {read} read");
        }
    }
    assert_eq!(
        got["message_count"].as_u64(),
        Some(counts.values().map(|c| c.1).sum()),
    );
    assert!(counts[&p1].1 >= 10, "{counts:?}");
    assert_eq!(got["topics"][&p1]["type"], "flume_msgs/msg/WaterLevel");
    let qos = &got["topics"][&p1]["qos"][0];
    assert_eq!(
        (&qos["reliability"], &qos["depth"]),
        (&"best_effort".into(), &5.into())
    );
    // Decoded by each reader from the definitions the bag carries: the same values.
    let level = |m: &Value| m["level_m"].clone();
    let q = |m: &Value| m["discharge_m3_per_s"].clone();
    let p1_predicted = |m: &Value| m["gauges"][0]["predicted_m"].clone();
    assert_eq!(values(&got, &p1, level), values(mcap, &p1, level));
    assert_eq!(values(&got, &inflow, q), values(mcap, &inflow, q));
    let predictions = values(&got, &predicted, p1_predicted);
    assert_eq!(predictions, values(mcap, &predicted, p1_predicted));
    assert!(
        predictions
            .iter()
            .any(|p| p.as_f64().is_some_and(|p| p > 0.04 && p < 0.15))
    );
    // The levels and discharges are the session's, in the order it played them.
    let session = read_mcap(
        &repo_file("tests/data/ulbra_session.mcap"),
        &["/gauges/p1", "/inflow"],
    );
    for (topic, theirs, field) in [
        (&p1, "/gauges/p1", &level as &dyn Fn(&Value) -> Value),
        (&inflow, "/inflow", &q),
    ] {
        let ours = values(&got, topic, field);
        let played = values(&session, theirs, field);
        assert!(
            ours.len() >= 2 && ours.len() <= played.len(),
            "{topic}: {}",
            ours.len()
        );
        assert_eq!(ours, played[..ours.len()], "{topic}");
    }
}

#[test]
fn sigterm_finishes_the_bag_and_kill_9_keeps_its_flushed_chunks() {
    let Some(_gpu) = gpu() else { return };
    if !python_has("mcap_ros2", "mcap mcap-ros2-support") || !python_has("rosbags", "rosbags") {
        return;
    }
    let dir = std::env::temp_dir().join(format!("flume-record-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");

    let whole = dir.join("whole");
    let twin = start(&whole);
    // Each second the node flushes a chunk of its inputs (30 gauge and 2 flow samples) and
    // outputs: a few seconds of the session.
    wait_for(&mcap_in(&whole), 40_000);
    let pid = twin.id().to_string();
    let status = Command::new("kill")
        .args(["-TERM", &pid])
        .status()
        .expect("kill");
    assert!(status.success());
    let out = twin.wait_with_output().expect("the twin exits");
    let log = printed(&out);
    assert!(out.status.success(), "{log}");
    assert!(
        log.contains("plays the sensors") && log.contains("terminated at"),
        "{log}"
    );
    let got = read_mcap(
        &mcap_in(&whole),
        &[full("gauges/p1"), full("inflow"), full("gauges/predicted")],
    );
    assert!(got["error"].is_null(), "{}", got["error"]);
    assert_eq!(got["profile"], "ros2");
    for topic in [
        "inflow",
        "gauges/p1",
        "gauges/p2",
        "gauges/p3",
        "/clock",
        "bed_profile",
        "eroded_mass",
        "gauges/predicted",
        "bed_marker",
        "particles",
        "/diagnostics",
    ] {
        let c = &got["channels"][full(topic)];
        assert!(
            count(&got, topic) > 0,
            "nothing on {topic}: {}",
            got["channels"]
        );
        assert_eq!(c["schema_encoding"], "ros2msg");
        assert_eq!(c["message_encoding"], "cdr");
    }
    // The session's levels, restamped on the twin's clock: now, not the session's 09:00.
    let levels: Vec<&Value> = got["messages"]
        .as_array()
        .expect("messages")
        .iter()
        .filter(|m| m["topic"] == full("gauges/p1").as_str())
        .collect();
    let now = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .expect("clock")
        .as_secs_f64();
    for m in &levels {
        let stamp = m["msg"]["header"]["stamp"]["sec"].as_f64().expect("sec");
        assert!((now - stamp).abs() < 600.0, "stamp {stamp} vs now {now}");
        let level = m["msg"]["level_m"].as_f64().expect("level");
        assert!((0.05..0.1).contains(&level), "{level}");
    }
    assert!(
        std::fs::read(mcap_in(&whole))
            .expect("reads")
            .ends_with(b"\x89MCAP0\r\n")
    );
    rosbags_agrees(&whole, &got, true);

    let killed = dir.join("killed");
    let mut twin = start(&killed);
    wait_for(&mcap_in(&killed), 40_000);
    twin.kill().expect("kill -9");
    twin.wait().expect("reaped");
    // The file ends as the last flush left it: an MCAP without a summary, which readers that
    // go to the end first open too.
    let got = read_mcap(
        &mcap_in(&killed),
        &[full("gauges/p1"), full("inflow"), full("gauges/predicted")],
    );
    assert!(got["error"].is_null(), "{}", got["error"]);
    assert!(
        count(&got, "gauges/p1") >= 10 && count(&got, "bed_profile") >= 1,
        "{}",
        got["channels"]
    );
    rosbags_agrees(&killed, &got, false);
    // The twin's own reader replays it, given the directory.
    let out = Command::new(env!("CARGO_BIN_EXE_flume-twin"))
        .current_dir(repo_file(""))
        .arg("replay")
        .arg(&killed)
        .args(["--config", "launch_configs/ulbra_flume.yaml"])
        .args(ULBRA_CI)
        .args(["--until", "0.1"])
        .output()
        .expect("replays");
    let log = printed(&out);
    assert!(out.status.success(), "{log}");
    assert!(log.contains("replayed 0.100 s"), "{log}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_directory_that_is_no_bag_is_refused_with_the_reason() {
    let dir = std::env::temp_dir().join(format!("flume-no-bag-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let replay = || {
        let out = Command::new(env!("CARGO_BIN_EXE_flume-twin"))
            .current_dir(repo_file(""))
            .arg("replay")
            .arg(&dir)
            .args(["--config", "launch_configs/ulbra_flume.yaml"])
            .output()
            .expect("runs");
        assert!(!out.status.success());
        printed(&out)
    };
    let log = replay();
    assert!(
        log.contains("holds no metadata.yaml and no .mcap file"),
        "{log}"
    );
    std::fs::write(
        dir.join("metadata.yaml"),
        "rosbag2_bagfile_information: {version: 9",
    )
    .expect("writes");
    let log = replay();
    assert!(log.contains("is not rosbag2 metadata"), "{log}");
    std::fs::remove_dir_all(&dir).ok();
}
