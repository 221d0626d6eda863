//! Particle frames over iceoryx2, read by the iceoryx2 Python binding
//! (`tests/interop/iox2_frames.py`): every particle of the flume in each frame, with the
//! header's version, count, phases and regions in range and finite values; a reader that
//! holds a frame and is killed leaves the twin running and the next reader served; a twin
//! killed with `kill -9` leaves shared memory that the next twin cleans up and reuses; a twin
//! stopped with SIGTERM ends cleanly; and the reference visualiser
//! (`scripts/rerun_visualiser.py`) writes frames that rerun's own reader reads back, and gives
//! up with an error, instead of waiting for ever, on a service no twin offers or one whose twin
//! has ended.

mod common;

use common::{gpu, printed, python_has, repo_file, ulbra_twin};
use iceoryx2::node::NodeView;
use iceoryx2::prelude::*;
use serde_json::Value;
use std::io::{BufRead, BufReader};
use std::path::Path;
use std::process::{Child, Command, Stdio};

/// The ULBRA flume at CI size: 4,582 particles.
const PARTICLES: u64 = 4582;

/// A twin that runs far past the test's end (it is killed or stopped), so that no reader can
/// come after its twin has finished.
fn twin(service: &str) -> Child {
    ulbra_twin()
        .args([
            "--no-replay",
            "--until",
            "600",
            "--frames-service",
            service,
            "--frames-rate-hz",
            "20",
            "--ros-args",
            "-r",
            &format!("__ns:=/flume_frames_{}", std::process::id()),
        ])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("starts the twin")
}

fn reader(service: &str, frames: usize, hold: bool) -> Child {
    let mut c = Command::new("python3");
    c.arg(repo_file("tests/interop/iox2_frames.py"))
        .args([service, &frames.to_string()]);
    if hold {
        c.arg("--hold");
    }
    c.stdout(Stdio::piped())
        .stderr(Stdio::inherit())
        .spawn()
        .expect("starts the reader")
}

/// The frames a reader printed, after checking each.
fn frames_of(child: Child) -> Vec<Value> {
    let out = child.wait_with_output().expect("the reader ends");
    assert!(out.status.success(), "the reader failed");
    let frames: Vec<Value> = String::from_utf8_lossy(&out.stdout)
        .lines()
        .map(|l| serde_json::from_str(l).expect("JSON"))
        .collect();
    for f in &frames {
        assert_eq!(f["version"], 1);
        assert_eq!(f["count"].as_u64(), Some(PARTICLES), "every particle");
        assert_eq!(
            f["slice_len"].as_u64(),
            Some(PARTICLES * 32),
            "32-byte particles"
        );
        assert_eq!(f["finite"], true);
        assert_eq!(f["units"], "m, m/s, kg/m3; flume frame z up");
        // The header's send time is this machine's clock in ns since the epoch: the frame was
        // read after it was sent, and within a minute (a header stamped on another clock, or
        // not stamped, is off by years). The figure goes to the log.
        let latency = f["latency_ms"].as_f64().expect("latency");
        assert!((0.0..60_000.0).contains(&latency), "{latency} ms");
        eprintln!("frame at t = {} s: latency {latency:.2} ms", f["t"]);
        let phases = f["phases"].as_object().expect("phases");
        let total: u64 = phases.values().map(|n| n.as_u64().expect("n")).sum();
        assert_eq!(total, PARTICLES);
        // Walls, water, sand and the parked water (phase 3).
        assert!(
            phases
                .keys()
                .all(|k| ["0", "1", "2", "3"].contains(&k.as_str())),
            "{f}"
        );
        assert_eq!(f["parked_phase"], 3);
        let regions = f["regions"].as_object().expect("regions");
        assert!(
            regions
                .keys()
                .all(|k| k.parse::<u8>().is_ok_and(|r| r <= 5)),
            "{f}"
        );
    }
    for w in frames.windows(2) {
        assert!(
            w[1]["step"].as_u64() > w[0]["step"].as_u64(),
            "frames move on"
        );
    }
    frames
}

/// The reference visualiser on `service`, saving `frames` frames to `rrd` and giving up after
/// `timeout_s` seconds without one.
fn visualiser(service: &str, frames: &str, timeout_s: &str, rrd: &Path) -> Command {
    let mut c = Command::new("python3");
    c.arg(repo_file("scripts/rerun_visualiser.py"))
        .args(["--service", service, "--frames", frames])
        .args(["--timeout", timeout_s, "--save"])
        .arg(rrd);
    c
}

/// Whether iceoryx2 still lists a dead node of process `pid` (what `kill -9` leaves behind).
fn dead_node_of(pid: u32) -> bool {
    let mut found = false;
    Node::<ipc::Service>::list(Config::global_config(), |state| {
        if let NodeState::Dead(view) = state {
            let of = view.id().pid::<ipc::Service>();
            found |= of.is_ok_and(|p| i64::from(p.value()) == i64::from(pid));
        }
        CallbackProgression::Continue
    })
    .expect("lists the iceoryx2 nodes");
    found
}

fn ends_well(twin: Child) -> String {
    let out = twin.wait_with_output().expect("the twin ends");
    let log = printed(&out);
    assert!(out.status.success(), "{log}");
    log
}

#[test]
fn python_reads_every_particle_and_dead_readers_or_twins_stall_nothing() {
    let Some(_gpu) = gpu() else { return };
    if !python_has("iceoryx2, rerun", "iceoryx2 rerun-sdk") {
        return;
    }
    let service = format!("flume_twin/test_{}", std::process::id());

    // A twin killed while running leaves its shared memory behind.
    let mut crashed = twin(&service);
    let first = frames_of(reader(&service, 1, false));
    assert_eq!(first.len(), 1);
    crashed.kill().expect("kill -9");
    crashed.wait().expect("reaped");
    assert!(dead_node_of(crashed.id()), "no dead node after kill -9");
    let rrd = std::env::temp_dir().join(format!("flume-frames-{}.rrd", std::process::id()));

    // The next twin cleans up and offers the service again; a reader holds a frame and is
    // killed; the twin runs on to its end and a new reader gets frames.
    let running = twin(&service);
    let mut stuck = reader(&service, 1, true);
    let mut lines = BufReader::new(stuck.stdout.take().expect("stdout")).lines();
    let frame = lines.next().expect("a frame").expect("a line");
    let _: Value = serde_json::from_str(&frame).expect("JSON");
    // The running twin removed the dead node when it started, or a twin of a test run beside
    // this one did (the same code; once it made this test's own log line a race).
    assert!(
        !dead_node_of(crashed.id()),
        "the killed twin's node is left"
    );
    assert_eq!(lines.next().expect("holding").expect("a line"), "holding");
    stuck.kill().expect("kill -9 the reader");
    stuck.wait().expect("reaped");
    let later = frames_of(reader(&service, 3, false));
    assert_eq!(later.len(), 3);
    let saved = visualiser(&service, "2", "120", &rrd)
        .status()
        .expect("runs the visualiser");
    assert!(saved.success());
    let read_back = Command::new("python3")
        .args([
            "-c",
            "import sys, rerun.chunk as c\n\
             rows = {}\n\
             for ch in c.RrdReader(sys.argv[1]).stream():\n\
             \x20   rows[str(ch.entity_path)] = rows.get(str(ch.entity_path), 0) + ch.num_rows\n\
             print(rows.get('/flume/by_phase', 0), rows.get('/flume/by_region', 0))",
        ])
        .arg(&rrd)
        .output()
        .expect("runs python3");
    assert!(
        read_back.status.success(),
        "{}",
        String::from_utf8_lossy(&read_back.stderr)
    );
    assert_eq!(
        String::from_utf8_lossy(&read_back.stdout).trim(),
        "2 2",
        "a frame per row"
    );
    // A visualiser that reads on while the twin is stopped: SIGTERM, as a launch system
    // stops the node, ends the twin cleanly (its last frame sent while a killed reader still
    // holds one), and the visualiser, its frames over, gives up instead of waiting for ever
    // (the wait that once hung this test on a twin that had ended).
    let mut watching = visualiser(&service, "1000000", "3", &rrd);
    let mut watching = watching
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("starts the visualiser");
    let mut said = BufReader::new(watching.stdout.take().expect("stdout")).lines();
    let first = said.next().expect("a line").expect("utf-8");
    assert_eq!(first, format!("reading particle frames from {service}"));
    let term = Command::new("kill")
        .args(["-TERM", &running.id().to_string()])
        .status()
        .expect("runs kill");
    assert!(term.success());
    let log = ends_well(running);
    // Polled, so that a visualiser that waits for ever fails the test instead of hanging it.
    let started = std::time::Instant::now();
    while watching.try_wait().expect("polls the visualiser").is_none() {
        if started.elapsed().as_secs() > 60 {
            watching.kill().ok();
            panic!("the visualiser still waits 60 s after the twin ended");
        }
        std::thread::sleep(std::time::Duration::from_millis(100));
    }
    let out = watching.wait_with_output().expect("the visualiser ends");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{err}");
    assert!(
        err.contains(&format!("no frame on {service} for 3 s")),
        "{err}"
    );
    std::fs::remove_file(&rrd).ok();
    assert!(log.contains("terminated at t = "), "{log}");
    assert!(log.contains("particle frames: iceoryx2 service"), "{log}");
}

/// `bench --frames` at the paper's count: a figure, not a timed test. What is checked is that
/// the reader took whole frames of every particle: their mean density is a flume's (water
/// 1000, sand 2650 kg/m3, walls between), not the zeros of an unwritten sample.
#[test]
fn the_frame_benchmark_reads_whole_frames_at_the_paper_s_count() {
    let Some(_gpu) = gpu() else { return };
    let out = Command::new(env!("CARGO_BIN_EXE_flume-twin"))
        .current_dir(repo_file(""))
        .args(["bench", "--frames", "--steps-seconds", "0.5"])
        .output()
        .expect("runs the benchmark");
    let log = printed(&out);
    assert!(out.status.success(), "{log}");
    assert!(
        log.contains("21978 particles, 703368 bytes a frame"),
        "{log}"
    );
    let line = log
        .lines()
        .find(|l| l.starts_with("the reader read every particle of "))
        .unwrap_or_else(|| panic!("no reader line:\n{log}"));
    let words: Vec<&str> = line.split_whitespace().collect();
    let read: u64 = words[6].parse().expect("frames read");
    assert!(read >= 1, "{line}");
    let density: f64 = words[words.iter().position(|w| *w == "density").expect("density") + 1]
        .parse()
        .expect("a mean density");
    assert!((1000.0..=2650.0).contains(&density), "{line}");
}

/// A visualiser asked for frames that never come says so and exits, rather than waiting
/// for ever (a batch job or a test would otherwise hang on a twin that has ended).
#[test]
fn the_visualiser_gives_up_on_a_service_no_twin_offers() {
    if !python_has("iceoryx2, rerun", "iceoryx2 rerun-sdk") {
        return;
    }
    let rrd = std::env::temp_dir().join(format!("flume-no-twin-{}.rrd", std::process::id()));
    let service = format!("flume_twin/nobody_{}", std::process::id());
    let out = visualiser(&service, "1", "2", &rrd)
        .output()
        .expect("runs the visualiser");
    std::fs::remove_file(&rrd).ok();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{err}");
    assert!(
        err.contains(&format!("no twin offered {service} within 2 s")),
        "{err}"
    );
}
