//! The live view (`run --foxglove`) against Foxglove's own client under Node
//! (`tests/interop/foxglove_client/client.mjs`: `@foxglove/ws-protocol`, with Foxglove's ROS 2
//! schema parser and CDR decoder): every topic of the twin is advertised with its ros2msg
//! schema and cdr encoding and decodes whole, with values a working twin gives; and a client
//! that subscribes and then never reads leaves the twin's pace as it was.

mod common;

use common::{Proc, csv_rows, repo_file, ulbra_twin};
use serde_json::Value;
use std::path::PathBuf;
use std::process::{Command, Stdio};
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// The tests of this file one at a time: each runs the twin on every core, and the stalled
/// client's test measures its pace.
static ONE_TWIN: Mutex<()> = Mutex::new(());

fn client_dir() -> PathBuf {
    repo_file("tests/interop/foxglove_client")
}

/// Whether Node and the client's packages are there (see `common::ready`).
fn node_client_ready() -> bool {
    let probe = Command::new("node")
        .current_dir(client_dir())
        .args(["-e", "import('@foxglove/ws-protocol')"])
        .output();
    common::ready(
        probe.is_ok_and(|o| o.status.success()),
        "Node cannot load the Foxglove client",
        "npm ci --prefix tests/interop/foxglove_client",
    )
}

/// The twin at CI size on the CPU backend, serving Foxglove on a port the system picks, in a
/// namespace of its own; `extra` are the test's options, `log` its RUST_LOG if not the default.
fn start_twin(ns: &str, extra: &[&str], log: Option<&str>) -> (Proc, String) {
    let mut cmd = ulbra_twin();
    if let Some(filter) = log {
        cmd.env("RUST_LOG", filter);
    }
    cmd.env("FLUME_TWIN_ADAPTER", "cpu")
        .args(["--foxglove", "0"])
        .args(extra)
        .args(["--ros-args", "-r", &format!("__ns:={ns}")]);
    let twin = Proc::spawn(&mut cmd);
    twin.wait_for("foxglove: ws://", Duration::from_secs(120));
    let url = twin
        .said()
        .lines()
        .find_map(|l| l.strip_prefix("foxglove: "))
        .expect("the address line")
        .to_string();
    (twin, url)
}

fn client(url: &str, seconds: u64, stall: bool) -> Proc {
    let mut cmd = Command::new("node");
    cmd.current_dir(client_dir())
        .args(["client.mjs", url, &seconds.to_string()]);
    if stall {
        cmd.arg("--stall");
    }
    Proc::spawn(cmd.stdin(Stdio::null()))
}

/// The JSON object a client printed last, whole.
fn printed_json(said: &str) -> Value {
    let line = said
        .lines()
        .rev()
        .find(|l| l.starts_with('{'))
        .unwrap_or_else(|| panic!("the client printed no JSON:\n{said}"));
    serde_json::from_str(line).unwrap_or_else(|e| panic!("{e}: {line}"))
}

/// How far a topic's stamps run, after checking that each is later than the one before (the
/// last output once went out twice, a rounding error short of --until and at it).
fn forward(topic: &Value) -> f64 {
    let stamps: Vec<f64> = topic["stamps"]
        .as_array()
        .expect("stamps")
        .iter()
        .map(num)
        .collect();
    assert!(stamps.windows(2).all(|w| w[1] > w[0]), "{stamps:?}");
    stamps.last().unwrap_or(&0.0) - stamps.first().unwrap_or(&0.0)
}

fn num(v: &Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}

#[test]
fn foxglove_s_client_decodes_every_topic_the_twin_serves() {
    let _one = ONE_TWIN.lock().unwrap_or_else(|p| p.into_inner());
    if !node_client_ready() {
        return;
    }
    let ns = format!("/flume_fox_{}", std::process::id());
    let out_dir = std::env::temp_dir().join(format!("flume-fox-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&out_dir);
    // The bundled session plays the sensors, so measured levels and the inflow flow too.
    let (mut twin, url) = start_twin(
        &ns,
        &[
            "--silent-wait-s",
            "0.5",
            "--until",
            "3",
            "--cloud-rate-hz",
            "4",
            "--out",
            out_dir.to_str().expect("utf-8"),
        ],
        None,
    );
    let mut viewer = client(&url, 300, false);
    let (ok, said) = twin.finish(Duration::from_secs(300));
    assert!(ok, "the twin failed:\n{said}");
    // The twin closed the connection on its way out: the client prints what it saw and ends.
    let (ok, seen) = viewer.finish(Duration::from_secs(20));
    assert!(ok, "the client failed:\n{seen}");
    let got = printed_json(&seen);

    let full = |t: &str| format!("{ns}/{t}");
    let expected = [
        (full("bed_profile"), "flume_msgs/msg/BedProfile"),
        (full("eroded_mass"), "flume_msgs/msg/ErodedMass"),
        (full("gauges/predicted"), "flume_msgs/msg/GaugeComparison"),
        (full("particles"), "sensor_msgs/msg/PointCloud2"),
        (full("bed_marker"), "visualization_msgs/msg/MarkerArray"),
        ("/clock".into(), "rosgraph_msgs/msg/Clock"),
        ("/diagnostics".into(), "diagnostic_msgs/msg/DiagnosticArray"),
        (full("inflow"), "flume_msgs/msg/Discharge"),
        (full("gauges/p1"), "flume_msgs/msg/WaterLevel"),
        (full("gauges/p2"), "flume_msgs/msg/WaterLevel"),
        (full("gauges/p3"), "flume_msgs/msg/WaterLevel"),
    ];
    let channels = got["channels"].as_array().expect("channels");
    assert_eq!(channels.len(), expected.len(), "{channels:?}");
    for (topic, schema) in &expected {
        let ch = channels
            .iter()
            .find(|c| c["topic"] == topic.as_str())
            .unwrap_or_else(|| panic!("{topic} is not advertised: {channels:?}"));
        assert_eq!(ch["schemaName"], *schema, "{ch}");
        assert_eq!(ch["schemaEncoding"], "ros2msg", "{ch}");
        assert_eq!(ch["encoding"], "cdr", "{ch}");
        // Every message came, and decoded to its last byte with the advertised schema.
        let t = &got["topics"][topic];
        assert!(num(&t["count"]) >= 1.0, "no message on {topic}");
        assert_eq!(t["trailing"], 0, "{topic}: a schema that does not fit");
    }
    let topic = |t: &str| &got["topics"][full(t)];

    // The predicted levels: three gauges, each a level inside the flume's depth, on stamps
    // that run forward; the bundled session's levels are the measured ones.
    let compare = topic("gauges/predicted");
    let gauges = compare["last"]["gauges"].as_array().expect("gauges");
    let names: Vec<&str> = gauges.iter().filter_map(|g| g["name"].as_str()).collect();
    assert_eq!(names, ["P1", "P2", "P3"]);
    // The last comparison the client decoded holds the solver's levels of one of its rows
    // (the twin's own gauges.csv), all three gauges at once.
    let rows = csv_rows(&out_dir.join("gauges.csv"));
    let level = |g: &Value| num(&g["predicted_m"]);
    let row_holds = |row: &std::collections::BTreeMap<String, String>| {
        gauges.iter().all(|g| {
            let name = g["name"].as_str().expect("a name");
            let solver: f64 = row[&format!("{name}_m")].parse().expect("a level");
            (level(g) - solver).abs() < 1e-6
        })
    };
    assert!(
        rows.iter().any(row_holds),
        "{gauges:?} is no row of gauges.csv"
    );
    for g in gauges {
        let predicted = level(g);
        assert!((0.0..0.3).contains(&predicted), "{g}");
        let measured = num(&g["measured_m"]);
        assert!((0.0..0.3).contains(&measured), "{g}");
        assert!((num(&g["residual_m"]) - (predicted - measured)).abs() < 1e-12);
    }
    assert!(forward(compare) > 1.0, "the comparisons span under 1 s");
    // /clock is simulated time: it runs forward, by about what the twin ran.
    let clock_span = forward(&got["topics"]["/clock"]);
    assert!(
        (1.5..=3.01).contains(&clock_span),
        "/clock spans {clock_span} s"
    );
    assert!(num(&topic("inflow")["last"]["discharge_m3_per_s"]) > 0.0);

    // The particles: every particle in the flow, laid out as the cloud's fields say, each
    // inside the flume (2.5 m long; 2-D, so y = 0).
    let particles: f64 = said
        .lines()
        .find_map(|l| l.strip_prefix("particles: "))
        .and_then(|n| n.parse().ok())
        .expect("a particles line");
    let cloud = &topic("particles")["last"];
    assert_eq!(
        cloud["fields"],
        serde_json::json!([
            ["x", 0, 7, 1],
            ["y", 4, 7, 1],
            ["z", 8, 7, 1],
            ["speed", 12, 7, 1],
            ["phase", 16, 2, 1]
        ])
    );
    // The reservoir's parked particles are left out: on this flume about half are in flow.
    let points = num(&cloud["points"]);
    assert!(points > 0.25 * particles && points <= particles, "{cloud}");
    assert_eq!(num(&cloud["bytes"]), points * 20.0, "{cloud}");
    assert_eq!(cloud["finite"], cloud["points"], "{cloud}");
    assert_eq!(
        cloud["phases"],
        serde_json::json!([0, 1, 2]),
        "walls, water, sand"
    );
    assert!(
        num(&cloud["lo"][0]) > -0.1 && num(&cloud["hi"][0]) < 2.6,
        "{cloud}"
    );
    let _ = std::fs::remove_dir_all(&out_dir);
}

/// Wall seconds the twin took from listening to reaching `--until`, and what it printed.
fn run_to_the_end(twin: &mut Proc) -> (f64, String) {
    twin.wait_for("listening:", Duration::from_secs(120));
    let started = Instant::now();
    twin.wait_for("reached t = ", Duration::from_secs(300));
    let wall = started.elapsed().as_secs_f64();
    let (ok, said) = twin.finish(Duration::from_secs(30));
    assert!(ok, "the twin failed:\n{said}");
    (wall, said)
}

#[test]
fn a_client_that_stops_reading_leaves_the_twin_s_pace_as_it_was() {
    let _one = ONE_TWIN.lock().unwrap_or_else(|p| p.into_inner());
    if !node_client_ready() {
        return;
    }
    let ns = |run: &str| format!("/flume_fox_{run}_{}", std::process::id());
    // Short chunks and a cloud per report: some MB/s of particles, so that a client that
    // reads nothing fills the socket's buffers and its queue on the server within seconds.
    let until = 4.0;
    let options = [
        "--no-replay",
        "--until",
        &until.to_string(),
        "--max-chunk-s",
        "0.01",
        "--cloud-rate-hz",
        "100",
    ];
    let (mut alone, _) = start_twin(&ns("alone"), &options, None);
    let (wall_alone, _) = run_to_the_end(&mut alone);

    // The server says (at info) when a client's queue is full and the oldest messages go.
    let log = Some("warn,rustdds=error,foxglove=info");
    let (mut twin, url) = start_twin(&ns("stalled"), &options, log);
    let stalled = client(&url, 300, true);
    stalled.wait_for("{\"stalled\"", Duration::from_secs(30));
    let mut reader = client(&url, 300, false);
    let (wall_stalled, said) = run_to_the_end(&mut twin);
    let (ok, seen) = reader.finish(Duration::from_secs(20));
    assert!(ok, "the reading client failed:\n{seen}");
    eprintln!(
        "the twin ran {until} s of simulated time in {wall_alone:.1} s alone, in {wall_stalled:.1} s beside a stalled client"
    );
    assert!(
        said.contains("outbox for client") && said.contains("full"),
        "the stalled client's queue never filled: the test did not stall it\n{said}"
    );
    assert!(
        wall_stalled < 1.5 * wall_alone,
        "the stalled client slowed the twin: {wall_stalled:.1} s against {wall_alone:.1} s"
    );
    // The other client was served to the end: its /clock (simulated time on this machine's
    // clock) spans the run but for the moment it took to connect.
    let got = printed_json(&seen);
    let span = forward(&got["topics"]["/clock"]);
    assert!(
        span > until - 1.5,
        "the reading client's /clock spans {span} s"
    );
}
