//! `ros2 param` and `ros2 service call` over rmw_cyclonedds, against the running twin: a Python
//! peer on Cyclone DDS (`tests/interop/ros_param_peer.py`, the `cyclonedds` wheel, nobody's
//! code here) calls the rcl_interfaces parameter services and the twin's triggers with
//! rmw_cyclonedds' request header and keeps only replies that echo it, as rclcpp and rclpy
//! do on that middleware. Every answer must be the twin's: the values the command line gave,
//! the twin's own reason for a refusal, the change announced on /parameter_events and then in
//! effect in the twin's /diagnostics, the simulated time held while paused.

mod common;

use common::{KillOnDrop, gpu, python_has, read_until, recycle_twin, repo_file};
use serde_json::Value;
use std::io::Read;
use std::process::{Command, Output, Stdio};

/// The peer's answers of kind `kind`, in order.
fn answers<'a>(lines: &'a [Value], kind: &str) -> Vec<&'a Value> {
    lines.iter().filter_map(|l| l.get(kind)).collect()
}

fn sim_time(diagnostics: &Value) -> f64 {
    diagnostics["sim_time_s"]
        .as_str()
        .and_then(|t| t.parse().ok())
        .unwrap_or_else(|| panic!("no sim_time_s in {diagnostics}"))
}

#[test]
fn a_cyclone_dds_client_sets_parameters_and_calls_the_services_as_ros2_cli_does() {
    let Some(_gpu) = gpu() else { return };
    if !python_has("cyclonedds", "cyclonedds") {
        return;
    }
    // What this test checks is the services, not discovery: a peer that never matched the
    // twin's services (RustDDS discovery on a loaded machine) starts again once, with a new
    // twin and a new participant, and says so; a second miss fails.
    let (mut peer, mut twin_log) = session();
    if !peer.status.success() && String::from_utf8_lossy(&peer.stderr).contains("never matched") {
        eprintln!("the twin's services were never matched: starting again");
        (peer, twin_log) = session();
    }
    let stdout = String::from_utf8_lossy(&peer.stdout);
    assert!(
        peer.status.success(),
        "the peer failed:\n{stdout}\n{}\ntwin:\n{twin_log}",
        String::from_utf8_lossy(&peer.stderr)
    );
    let lines: Vec<Value> = stdout
        .lines()
        .map(|l| serde_json::from_str(l).unwrap_or_else(|e| panic!("{e}: {l}")))
        .collect();
    check_parameters(&lines);
    check_triggers(&lines, &twin_log);
    // Each request reaches both of a service's servers; the one of the other mapping must
    // stay quiet, and a normal run says nothing alarming.
    assert!(!twin_log.contains("ERROR"), "{twin_log}");
    assert!(!twin_log.contains("related_sample_identity"), "{twin_log}");
}

/// A twin and the peer's session against it: the peer's output, and all the twin printed.
fn session() -> (Output, String) {
    let mut twin = KillOnDrop(
        recycle_twin()
            .args(["--ros-args", "-r", "__ns:=/flume_cy"])
            .args([
                "-p",
                "target_real_time_factor:=0.5",
                "-p",
                "gauge_mount_height_m.p1:=0.2",
            ])
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .expect("the twin starts"),
    );
    // The peer's participant starts after the twin's node, as a user's `ros2 param` would.
    let (seen, drained) = read_until(twin.0.stdout.take().expect("stdout"), "node:");
    let mut err = twin.0.stderr.take().expect("stderr");
    let errors = std::thread::spawn(move || {
        let mut text = String::new();
        let _ = err.read_to_string(&mut text);
        text
    });
    let peer = Command::new("python3")
        .arg(repo_file("tests/interop/ros_param_peer.py"))
        .arg("/flume_cy/flume_twin")
        .output()
        .expect("the peer runs");
    let _ = twin.0.kill();
    let _ = twin.0.wait();
    let twin_log = seen + &drained.join().expect("twin output") + &errors.join().expect("stderr");
    (peer, twin_log)
}

fn check_parameters(lines: &[Value]) {
    let names = &answers(lines, "list")[0]["names"];
    let expected = [
        "frame_id",
        "gauge_mount_height_m.p1",
        "publish_rate_hz",
        "stale_after_s",
        "target_real_time_factor",
        "use_sim_time",
    ];
    assert_eq!(names, &serde_json::json!(expected));
    // target_real_time_factor, frame_id, gauge_mount_height_m.p1, no_such: the first and
    // third as `-p` gave them, not the defaults; an unknown name NOT_SET.
    assert_eq!(
        answers(lines, "get")[0]["values"],
        serde_json::json!([0.5, "flume", 0.2, null])
    );
    assert_eq!(
        answers(lines, "types")[0]["types"],
        serde_json::json!([3, 4, 3, 0])
    );
    let described = &answers(lines, "describe")[0]["descriptors"];
    assert_eq!(described[0]["type"], 3);
    let text = described[0]["description"].as_str().expect("text");
    assert!(text.contains("range sensor"), "{text}");
    assert_eq!(described[1]["type"], 0);

    let sets = answers(lines, "set");
    assert_eq!(sets.len(), 3, "{sets:?}");
    assert_eq!(sets[0]["successful"], false);
    let reason = sets[0]["reason"].as_str().expect("reason");
    assert!(reason.contains("must be a positive number"), "{reason}");
    assert_eq!(
        sets[1]["successful"], false,
        "an integer frame_id: {:?}",
        sets[1]
    );
    assert_eq!(sets[2]["successful"], true, "{:?}", sets[2]);
    let event = &answers(lines, "event")[0]["event"];
    assert_eq!(event["node"], "/flume_cy/flume_twin");
    assert_eq!(event["changed"]["target_real_time_factor"], 0.25);
    // The twin itself runs on the new value: its status reports it.
    let status = &answers(lines, "diagnostics_after_set")[0]["values"];
    assert_eq!(status["target_real_time_factor"], "0.25", "{status}");
}

fn check_triggers(lines: &[Value], twin_log: &str) {
    let calls = answers(lines, "trigger");
    let said = |k: usize, service: &str, starts: &str| {
        assert_eq!(calls[k]["service"], service);
        assert_eq!(calls[k]["success"], true, "{:?}", calls[k]);
        let message = calls[k]["message"].as_str().expect("message");
        assert!(message.starts_with(starts), "{service}: {message}");
    };
    assert_eq!(calls.len(), 4, "{calls:?}");
    said(0, "pause", "paused at t =");
    said(1, "step", "stepping from t =");
    said(2, "resume", "resumed at t =");
    said(3, "reset", "resetting");
    let paused = &answers(lines, "paused")[0];
    assert_eq!(paused["later"]["paused"], "true", "{paused}");
    assert_eq!(
        sim_time(&paused["first"]),
        sim_time(&paused["later"]),
        "time ran while paused"
    );
    let resumed = &answers(lines, "resumed")[0];
    assert!(
        sim_time(&resumed["later"]) > sim_time(&resumed["first"]),
        "time did not run after resume: {resumed}"
    );
    // Each call acted once: two servers see every request.
    for service in ["Pause", "Step", "Resume", "Reset"] {
        let acted = twin_log.matches(&format!("service {service}:")).count();
        assert_eq!(acted, 1, "{service} acted {acted} times:\n{twin_log}");
    }
}
