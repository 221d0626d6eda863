//! The node's recording (`run --record`), with the bundled session playing the sensors (no
//! sensor is on the network): SIGTERM finishes the file, which an independent reader (Python
//! `mcap` + `mcap-ros2-support`) reads whole, every input and output topic with its schema;
//! `kill -9` leaves a file that the same reader, and the twin's replay, read up to the last
//! flushed chunk.

mod common;

use common::{ULBRA_CI, gpu, printed, python_has, read_mcap, repo_file, ulbra_twin};
use serde_json::Value;
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

/// The recording as Python reads it, with the gauge P1's levels decoded.
fn read_p1(path: &Path) -> Value {
    read_mcap(path, &[format!("{}/gauges/p1", ns())])
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

#[test]
fn sigterm_finishes_the_recording_and_kill_9_keeps_its_flushed_chunks() {
    let Some(_gpu) = gpu() else { return };
    if !python_has("mcap_ros2", "mcap mcap-ros2-support") {
        return;
    }
    let dir = std::env::temp_dir().join(format!("flume-record-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");

    let whole = dir.join("whole.mcap");
    let twin = start(&whole);
    // Each second the node flushes a chunk of its inputs (30 gauge and 2 flow samples) and
    // outputs: a few seconds of the session.
    wait_for(&whole, 40_000);
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
    let got = read_p1(&whole);
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
        std::fs::read(&whole)
            .expect("reads")
            .ends_with(b"\x89MCAP0\r\n")
    );

    let killed = dir.join("killed.mcap");
    let mut twin = start(&killed);
    wait_for(&killed, 40_000);
    twin.kill().expect("kill -9");
    twin.wait().expect("reaped");
    let got = read_p1(&killed);
    let error = got["error"].as_str().unwrap_or_default();
    assert!(
        !error.is_empty(),
        "a killed recording has no footer: the reader stops at its end"
    );
    assert!(
        count(&got, "gauges/p1") >= 10 && count(&got, "bed_profile") >= 1,
        "{}",
        got["channels"]
    );
    assert!(
        !std::fs::read(&killed)
            .expect("reads")
            .ends_with(b"\x89MCAP0\r\n")
    );
    // The twin's own reader replays it up to the damage.
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
    assert!(
        log.contains("is damaged: read") && log.contains("replayed 0.100 s"),
        "{log}"
    );
    std::fs::remove_dir_all(&dir).ok();
}
