//! `replay --publish`: the bundled session played on the wire with /clock, as `ros2 bag play
//! --clock` does, to a twin on simulated time (`use_sim_time:=true`) in another process, with a
//! Cyclone DDS listener (`tests/interop/dds_listen.py`, a DDS nobody here wrote) checking what
//! went on the wire against the recording itself.

mod common;

use common::{Proc, gpu, printed, python_has, read_mcap, repo_file, ulbra_twin};
use serde_json::Value;
use std::path::Path;
use std::process::Command;
use std::time::Duration;

/// The player's and the twin's DDS domain, away from the other tests' traffic.
const DOMAIN: &str = "7";
/// Recorded seconds played, and how fast.
const PLAYED_S: f64 = 6.0;
const RATE: f64 = 2.0;

fn stamp(v: &Value) -> f64 {
    v["sec"].as_f64().expect("sec") + v["nanosec"].as_f64().expect("nanosec") * 1e-9
}

/// The CI-size ULBRA twin on simulated time on DDS domain `domain`, recording to `record`,
/// with `extra` options; once it has subscribed.
fn twin_on_sim_time(domain: &str, record: &Path, extra: &[&str]) -> Proc {
    let twin = Proc::spawn(
        ulbra_twin()
            .args(["--domain-id", domain, "--no-frames"])
            .args(extra)
            .arg("--record")
            .arg(record)
            .args(["--ros-args", "-p", "use_sim_time:=true"]),
    );
    twin.wait_for("listening:", Duration::from_secs(120));
    twin
}

/// The bundled session played on DDS domain `domain` with `extra` options: whether the
/// player succeeded, and what it printed.
fn play(domain: &str, extra: &[&str]) -> (bool, String) {
    Proc::spawn(
        Command::new(env!("CARGO_BIN_EXE_flume-twin"))
            .arg("replay")
            .arg(repo_file("tests/data/ulbra_session.mcap"))
            .args(["--publish", "--loopback", "--domain-id", domain])
            .args(extra),
    )
    .finish(Duration::from_secs(60))
}

#[test]
fn a_session_played_on_the_wire_drives_a_twin_on_simulated_time() {
    let Some(_gpu) = gpu() else { return };
    if !python_has(
        "cyclonedds, mcap, mcap_ros2",
        "cyclonedds mcap mcap-ros2-support",
    ) {
        return;
    }
    let dir = std::env::temp_dir().join(format!("flume-play-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("temp dir");
    let session = repo_file("tests/data/ulbra_session.mcap");
    let sensors = ["/inflow", "/gauges/p1", "/gauges/p2", "/gauges/p3"];
    let recorded = read_mcap(&session, &sensors);
    let recorded = recorded["messages"].as_array().expect("messages");
    let t0 = recorded
        .iter()
        .map(|m| m["log_time"].as_f64().expect("log time") * 1e-9)
        .fold(f64::INFINITY, f64::min);
    let played: Vec<&Value> = recorded
        .iter()
        .filter(|m| m["log_time"].as_f64().expect("log time") * 1e-9 <= t0 + PLAYED_S)
        .collect();
    let on = |topic: &str| -> Vec<(f64, f64)> {
        played
            .iter()
            .filter(|m| m["topic"] == topic)
            .map(|m| {
                let v = &m["msg"];
                let x = v.get("discharge_m3_per_s").unwrap_or(&v["level_m"]);
                (stamp(&v["header"]["stamp"]), x.as_f64().expect("value"))
            })
            .collect()
    };

    // The twin first, in the root namespace where the recording's topics are, then the
    // listener; the player once both have subscribed, and /clock holds for --delay-s before
    // the first sample while DDS matches them.
    let twin_rec = dir.join("twin.mcap");
    let mut twin = twin_on_sim_time(DOMAIN, &twin_rec, &["--until", "0.3"]);
    let mut listener = Proc::spawn(
        Command::new("python3")
            .arg(repo_file("tests/interop/dds_listen.py"))
            .args([DOMAIN, "/", "180", "5"]),
    );
    listener.wait_for("{\"listening\"", Duration::from_secs(60));
    let (ok, player_log) = play(
        DOMAIN,
        &[
            "--until",
            &PLAYED_S.to_string(),
            "--rate",
            &RATE.to_string(),
            "--delay-s",
            "3",
        ],
    );
    assert!(ok, "the player failed:\n{player_log}");
    let (ok, twin_log) = twin.finish(Duration::from_secs(600));
    assert!(ok, "the twin failed:\n{twin_log}");
    let (_, heard) = listener.finish(Duration::from_secs(200));
    assert!(
        !heard.contains("Traceback"),
        "the listener failed:\n{heard}"
    );

    // The player: every sample of the window, paced: the last goes out no sooner than its
    // log time, from the first, over RATE (a lower bound, which no slow machine breaks).
    let line = player_log
        .lines()
        .find(|l| l.starts_with("played "))
        .unwrap_or_else(|| panic!("no summary:\n{player_log}"));
    let words: Vec<&str> = line.split_whitespace().collect();
    assert_eq!(words[1].parse::<usize>().ok(), Some(played.len()), "{line}");
    let wall: f64 = words[words.iter().position(|w| *w == "in").expect("in") + 1]
        .parse()
        .expect("seconds");
    let last_s = played
        .iter()
        .map(|m| m["log_time"].as_f64().expect("log time") * 1e-9 - t0)
        .fold(0.0, f64::max);
    assert!(
        wall >= last_s / RATE,
        "{line}: the last sample is {last_s:.3} s in"
    );

    // The wire, as Cyclone DDS read it: /clock on the recording's time, only the player's
    // (a twin on simulated time publishes none), from the start to the end of the window;
    // the inflow (reliable) sample for sample as recorded, stamps unchanged; the gauges (best
    // effort) each as recorded.
    let lines: Vec<Value> = heard
        .lines()
        .filter_map(|l| serde_json::from_str(l).ok())
        .collect();
    let clocks: Vec<f64> = lines.iter().filter_map(|v| v["clock"].as_f64()).collect();
    assert!(clocks.len() > 10, "{} /clock messages", clocks.len());
    // 1 µs: the clock's nanoseconds against a float of seconds since the epoch.
    assert!(
        (clocks[0] - t0).abs() < 1e-6,
        "first /clock {} vs {t0}",
        clocks[0]
    );
    assert!(clocks.windows(2).all(|w| w[1] >= w[0]), "/clock went back");
    let last = clocks.last().copied().unwrap_or(0.0);
    assert!(
        last <= t0 + PLAYED_S + 1e-6 && last >= t0 + PLAYED_S - 0.1,
        "last /clock {:.3} s into the recording",
        last - t0
    );
    let got = |name: &str| -> Vec<(f64, f64)> {
        lines
            .iter()
            .filter_map(|v| v.get(name))
            .map(|v| {
                let x = v.get("q").unwrap_or(&v["level"]);
                (
                    v["stamp"].as_f64().expect("stamp"),
                    x.as_f64().expect("value"),
                )
            })
            .collect()
    };
    assert_eq!(got("inflow"), on("/inflow"), "the inflow on the wire");
    for g in ["p1", "p2", "p3"] {
        let (sent, heard) = (on(&format!("/gauges/{g}")), got(g));
        assert!(
            heard.iter().all(|s| sent.contains(s)),
            "{g}: a sample that is not the recording's"
        );
        // Best effort over loopback loses little; 90 % leaves room for a loaded machine.
        assert!(
            heard.len() * 10 >= sent.len() * 9,
            "{g}: {} of {} samples heard",
            heard.len(),
            sent.len()
        );
    }

    // The twin followed the player's clock: its outputs are stamped on the recording's time
    // and compare with gauges that are not stale on that clock.
    assert!(twin_log.contains("simulated time started at"), "{twin_log}");
    assert!(twin_log.contains("reached t = 0.300 s"), "{twin_log}");
    let out = read_mcap(&twin_rec, &["/gauges/predicted", "/inflow"]);
    assert!(
        out["channels"].get("/clock").is_none(),
        "a twin on simulated time publishes no /clock"
    );
    let messages = out["messages"].as_array().expect("messages");
    let inflow_in: Vec<f64> = messages
        .iter()
        .filter(|m| m["topic"] == "/inflow")
        .map(|m| stamp(&m["msg"]["header"]["stamp"]))
        .collect();
    assert!(!inflow_in.is_empty(), "the twin took no inflow");
    assert!(
        inflow_in
            .iter()
            .all(|s| on("/inflow").iter().any(|(t, _)| t == s)),
        "the twin's inputs are the recording's samples"
    );
    let predicted: Vec<&Value> = messages
        .iter()
        .filter(|m| m["topic"] == "/gauges/predicted")
        .map(|m| &m["msg"])
        .collect();
    assert!(!predicted.is_empty());
    for p in &predicted {
        let s = stamp(&p["header"]["stamp"]);
        // The outputs' stamps are the first sample heard (t = 0) plus simulated time (to
        // 0.3 s); 50 ms, half a gauge's period, covers which sample came first.
        assert!(
            s >= t0 - 1e-3 && s <= t0 + 0.3 + 0.05,
            "an output stamped {:.4} s from the recording's start",
            s - t0
        );
    }
    let final_gauges = predicted.last().expect("an output")["gauges"]
        .as_array()
        .expect("gauges");
    for g in final_gauges {
        assert!(g["measured_m"].as_f64().is_some(), "{g}");
        assert_eq!(g["stale"], false, "{g}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_clock_that_goes_back_resets_the_twin_for_a_new_session() {
    let Some(_gpu) = gpu() else { return };
    if !python_has("mcap, mcap_ros2", "mcap mcap-ros2-support") {
        return;
    }
    let dir = std::env::temp_dir().join(format!("flume-play-back-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("temp dir");
    let domain = "8";
    let twin_rec = dir.join("twin.mcap");
    let mut twin = twin_on_sim_time(domain, &twin_rec, &[]);
    // The same 2 s twice: the second time /clock jumps back 2 s, as a restarted player's does.
    for _ in 0..2 {
        let (ok, log) = play(domain, &["--until", "2", "--rate", "2", "--delay-s", "2"]);
        assert!(ok, "the player failed:\n{log}");
    }
    twin.wait_for(
        "reset to the case's initial state",
        Duration::from_secs(300),
    );
    // A few outputs of the new session, then SIGTERM finishes the recording.
    std::thread::sleep(Duration::from_secs(5));
    let status = Command::new("kill")
        .args(["-TERM", &twin.pid().to_string()])
        .status()
        .expect("kill");
    assert!(status.success());
    let (ok, log) = twin.finish(Duration::from_secs(60));
    assert!(ok, "the twin failed:\n{log}");
    assert!(log.contains("/clock went back: the twin resets"), "{log}");
    // On the new session's clock, nothing the second player sent was refused (the old run's
    // stamps would have made every one out of order) and no gauge is stale.
    let out = read_mcap(&twin_rec, &["/diagnostics"]);
    let last = out["messages"]
        .as_array()
        .expect("messages")
        .last()
        .expect("diagnostics")["msg"]["status"][0]["values"]
        .as_array()
        .expect("values")
        .iter()
        .map(|kv| {
            (
                kv["key"].as_str().unwrap_or(""),
                kv["value"].as_str().unwrap_or(""),
            )
        })
        .map(|(k, v)| (k.to_string(), v.to_string()))
        .collect::<std::collections::BTreeMap<String, String>>();
    assert_eq!(last["rejected_inputs"], "0", "{last:?}");
    assert_eq!(last["stale_sensors"], "", "{last:?}");
    assert_eq!(last["sensor_driven"], "true", "{last:?}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn publish_takes_no_twin_options_and_a_replay_checks_its_mounts() {
    for extra in [
        vec!["--config", "launch_configs/ulbra_flume.yaml"],
        vec!["--out", "x.mcap"],
    ] {
        let out = Command::new(env!("CARGO_BIN_EXE_flume-twin"))
            .arg("replay")
            .arg(repo_file("tests/data/ulbra_session.mcap"))
            .arg("--publish")
            .args(&extra)
            .output()
            .expect("runs");
        assert!(!out.status.success(), "{extra:?} was taken");
        assert!(
            printed(&out).contains("cannot be used with"),
            "{}",
            printed(&out)
        );
    }
    // An in-process replay takes the live twin's range-sensor mounts, validated as it does.
    let out = Command::new(env!("CARGO_BIN_EXE_flume-twin"))
        .arg("replay")
        .arg(repo_file("tests/data/ulbra_session.mcap"))
        .arg("--config")
        .arg(repo_file("launch_configs/ulbra_flume.yaml"))
        .args(["--ros-args", "-p", "gauge_mount_height_m.p1:=-0.2"])
        .output()
        .expect("runs");
    assert!(!out.status.success());
    assert!(
        printed(&out).contains("gauge_mount_height_m.p1: must be a positive number"),
        "{}",
        printed(&out)
    );
}
