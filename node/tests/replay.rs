//! The twin end to end from the bundled session (`tests/data/ulbra_session.mcap`): replayed
//! in-process at CI size, twice, the output recordings are the same bytes; an independent
//! reader (Python `mcap` + `mcap-ros2-support`) decodes every message of it with the schema
//! the file carries; the values are the solver's (the `--csv` rows); and the outputs make
//! physical sense for the first seconds of the session. A recording that is cut short or
//! damaged replays up to the damage, with a message that says so.

mod common;

use common::{ULBRA_CI, csv_rows, gpu, printed, python_has, read_mcap, repo_file};
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::Command;

const DP: f64 = 0.01;
const BED_M: f64 = 0.055;
/// The session's start (its stamps' origin), s since the epoch.
const ORIGIN_S: f64 = 1_795_251_600.0;

fn session() -> PathBuf {
    repo_file("tests/data/ulbra_session.mcap")
}

fn replay(recording: &Path, extra: &[&str]) -> (bool, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_flume-twin"))
        .arg("replay")
        .arg(recording)
        .arg("--config")
        .arg(repo_file("launch_configs/ulbra_flume.yaml"))
        .args(ULBRA_CI)
        .args(extra)
        .output()
        .expect("runs the binary");
    let log = printed(&out);
    (out.status.success(), log)
}

fn num(v: &Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}

fn secs(stamp: &Value) -> f64 {
    num(&stamp["sec"]) + num(&stamp["nanosec"]) * 1e-9 - ORIGIN_S
}

#[test]
fn the_bundled_session_replays_bit_identically_and_makes_physical_sense() {
    let Some(_gpu) = gpu() else { return };
    if !python_has("mcap_ros2", "mcap mcap-ros2-support") {
        return;
    }
    let dir = std::env::temp_dir().join(format!("flume-replay-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let (a, b, csv) = (dir.join("a.mcap"), dir.join("b.mcap"), dir.join("csv"));
    let until = "2.0";
    for (out, extra) in [
        (&a, vec!["--csv", csv.to_str().expect("utf-8")]),
        (&b, vec![]),
    ] {
        let mut args = vec!["--until", until, "--out", out.to_str().expect("utf-8")];
        args.extend(extra);
        let (ok, log) = replay(&session(), &args);
        eprintln!("{log}");
        assert!(ok, "the replay failed:\n{log}");
        assert!(log.contains("replayed 2.000 s"), "{log}");
    }
    let (bytes_a, bytes_b) = (std::fs::read(&a).expect("a"), std::fs::read(&b).expect("b"));
    assert!(
        bytes_a == bytes_b,
        "two replays of the same recording differ"
    );

    let outputs = [
        "/gauges/predicted",
        "/bed_profile",
        "/eroded_mass",
        "/clock",
    ];
    let got = read_mcap(&a, &outputs);
    assert!(got["error"].is_null(), "{}", got["error"]);
    assert_eq!(got["profile"], "ros2");
    let channels = got["channels"].as_object().expect("channels");
    for (topic, schema, count) in [
        ("/inflow", "flume_msgs/msg/Discharge", 5),
        ("/gauges/p1", "flume_msgs/msg/WaterLevel", 21),
        ("/gauges/p3", "flume_msgs/msg/WaterLevel", 21),
        ("/gauges/predicted", "flume_msgs/msg/GaugeComparison", 21),
        ("/bed_profile", "flume_msgs/msg/BedProfile", 21),
        ("/eroded_mass", "flume_msgs/msg/ErodedMass", 21),
        ("/bed_marker", "visualization_msgs/msg/MarkerArray", 21),
        ("/clock", "rosgraph_msgs/msg/Clock", 21),
    ] {
        let c = &channels[topic];
        assert_eq!(c["schema_name"], schema, "{topic}");
        assert_eq!(c["schema_encoding"], "ros2msg", "{topic}");
        assert_eq!(c["message_encoding"], "cdr", "{topic}");
        assert!(
            c["qos"]
                .as_str()
                .is_some_and(|q| q.contains("history: keep_last")),
            "{topic}"
        );
        // Inputs from 0 to 2 s: the flow meter at 2 Hz, the gauges at 10 Hz; an output at 0
        // and at each 0.1 s.
        assert_eq!(num(&c["count"]) as u64, count, "{topic}");
    }
    let messages = got["messages"].as_array().expect("messages");
    let of = |topic: &str| -> Vec<&Value> {
        messages
            .iter()
            .filter(|m| m["topic"] == topic)
            .map(|m| &m["msg"])
            .collect()
    };

    // The values are the solver's: each predicted level is gauges.csv's at its time, and the
    // inlet ran at the recorded discharge (eroded_mass.csv's inflow column).
    let gauges = csv_rows(&csv.join("gauges.csv"));
    let compare = of("/gauges/predicted");
    for (c, row) in compare.iter().zip(&gauges) {
        let t = secs(&c["header"]["stamp"]);
        assert!((t - row["time_s"].parse::<f64>().expect("t")).abs() < 1e-6);
        for (k, g) in c["gauges"].as_array().expect("gauges").iter().enumerate() {
            let name = format!("P{}", k + 1);
            assert_eq!(g["name"], name.as_str());
            let csv_level: f64 = row[&format!("{name}_m")].parse().expect("level");
            assert!(
                (num(&g["predicted_m"]) - csv_level).abs() < 1e-6,
                "{name} at {t}"
            );
        }
    }
    let recorded_inflow: Vec<(f64, f64)> = read_mcap(&session(), &["/inflow"])["messages"]
        .as_array()
        .expect("messages")
        .iter()
        .map(|m| {
            (
                secs(&m["msg"]["header"]["stamp"]),
                num(&m["msg"]["discharge_m3_per_s"]),
            )
        })
        .collect();
    for row in csv_rows(&csv.join("eroded_mass.csv")).iter().skip(1) {
        let t: f64 = row["time_s"].parse().expect("t");
        let q: f64 = row["inflow_m3_per_s"].parse().expect("q");
        let due = recorded_inflow
            .iter()
            .rev()
            .find(|(ts, _)| *ts <= t + 1e-9)
            .expect("a discharge in force");
        assert!(
            (q - due.1).abs() < 1e-12,
            "at {t} s the inlet ran {q}, recorded {}",
            due.1
        );
    }

    // Physics in the first 2 s. The recorded gauges come from a hydraulic model whose front
    // reaches P1 (x = 0.5 m) at about 2 s and the weir at 10 s, as the experiment's 8 s; at
    // dp = 1 cm the twin's front runs ahead as a thin sheet (the paper's Figure 9a: the front
    // converges only at dp <= 4 mm). So: at P2 and P3, dry or under a film in both, the twin
    // is within dp / 2 of the gauge plus three sensor sigmas (0.5 mm each); at P1 the twin is
    // wet and below the level the recording settles at. The jet wears the bed under it at van
    // Rijn's rate, worn away (the twin's pick-up), and in 2 s no grain has lost all of its
    // mass: Zb over x = 0.15-0.5 m stays within dp / 10 (measured: -0.008 mm). The chance
    // pick-up lifted a particle in four columns by then (Zb -2.3 mm), the paper's release the
    // whole top row (more than dp / 2): either fails it.
    for c in &compare {
        let t = secs(&c["header"]["stamp"]);
        for g in &c["gauges"].as_array().expect("gauges")[1..] {
            let (p, m) = (num(&g["predicted_m"]), num(&g["measured_m"]));
            assert!(
                (p - m).abs() <= DP / 2.0 + 1.5e-3,
                "{} at {t:.1} s: {p} vs {m}",
                g["name"]
            );
        }
    }
    let last = compare.last().expect("outputs");
    let p1 = num(&last["gauges"][0]["predicted_m"]);
    let settled = read_mcap(&session(), &["/gauges/p1"])["messages"]
        .as_array()
        .expect("messages")
        .iter()
        .map(|m| num(&m["msg"]["level_m"]))
        .fold(0.0, f64::max);
    assert!(
        p1 > BED_M + DP / 2.0 && p1 < settled,
        "P1 at 2 s: {p1} (settles at {settled})"
    );
    // Each published eroded mass is the solver's at its time (eroded_mass.csv), to the bit.
    let eroded = of("/eroded_mass");
    let eroded_rows = csv_rows(&csv.join("eroded_mass.csv"));
    assert_eq!(eroded.len(), eroded_rows.len());
    for (m, row) in eroded.iter().zip(&eroded_rows) {
        let t = secs(&m["header"]["stamp"]);
        assert!((t - row["time_s"].parse::<f64>().expect("t")).abs() < 1e-6);
        for (field, column) in [
            ("eroded_kg", "eroded_kg"),
            ("eroded_kg_per_m", "eroded_kg_per_m"),
            ("rate_kg_per_s", "eroded_rate_kg_per_s"),
            ("particles", "eroded_particles"),
        ] {
            let csv_value: f64 = row[column].parse().expect("a number");
            assert_eq!(num(&m[field]), csv_value, "{field} at {t} s");
        }
    }
    let beds = of("/bed_profile");
    let mean_zb = |bed: &Value| {
        let zs: Vec<f64> = bed["x_m"]
            .as_array()
            .expect("x")
            .iter()
            .zip(bed["zb_m"].as_array().expect("zb"))
            .filter(|(x, _)| (0.15..=0.5).contains(&num(x)))
            .map(|(_, z)| num(z))
            .collect();
        zs.iter().sum::<f64>() / zs.len() as f64
    };
    // The profile at t = 0 has no Zb: the grains' regions are first classified by a step.
    let (zb0, zb1) = (mean_zb(beds[1]), mean_zb(beds[beds.len() - 1]));
    eprintln!(
        "P1 at 2 s {p1:.4} m (settles at {settled:.4}); Zb under the jet {zb0:.4} -> {zb1:.4} m"
    );
    assert!(
        (zb1 - zb0).abs() <= DP / 10.0,
        "the bed under the jet: {zb0} -> {zb1}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// A byte in the compressed records of the middle chunk of an MCAP file (records are an
/// opcode, a u64 length and the body; chunks are opcode 0x06). A flip elsewhere, in a message
/// index, would not touch a message.
fn inside_a_middle_chunk(bytes: &[u8]) -> usize {
    let mut chunks = Vec::new();
    let mut at = 8;
    while at + 9 <= bytes.len() {
        let len = u64::from_le_bytes(bytes[at + 1..at + 9].try_into().expect("8 bytes")) as usize;
        if bytes[at] == 0x06 {
            chunks.push((at + 9, len));
        }
        at += 9 + len;
    }
    let (body, len) = chunks[chunks.len() / 2];
    body + len - len / 4
}

#[test]
fn a_damaged_recording_replays_up_to_the_damage() {
    let dir = std::env::temp_dir().join(format!("flume-replay-damage-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let junk = dir.join("junk.mcap");
    std::fs::write(&junk, b"this is not a recording").expect("writes");
    let (ok, log) = replay(&junk, &[]);
    assert!(!ok && log.contains("is not an MCAP recording"), "{log}");
    let Some(_gpu) = gpu() else { return };
    let bytes = std::fs::read(session()).expect("the bundled session");
    let cut = dir.join("cut.mcap");
    std::fs::write(&cut, &bytes[..bytes.len() / 3]).expect("writes");
    let mut flipped = bytes.clone();
    flipped[inside_a_middle_chunk(&bytes)] ^= 0x04;
    let bad = dir.join("flipped.mcap");
    std::fs::write(&bad, &flipped).expect("writes");
    for damaged in [cut, bad] {
        let (ok, log) = replay(&damaged, &["--until", "0.2"]);
        assert!(ok, "{log}");
        assert!(
            log.contains("is damaged: read") && log.contains("replaying what comes before it"),
            "{log}"
        );
        assert!(log.contains("replayed 0.200 s"), "{log}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// The bundled session is what its documented command makes, byte for byte: anyone can
/// remake it (README, "Recording and replay").
#[test]
fn the_bundled_session_is_remade_by_its_generator() {
    let out = std::env::temp_dir().join(format!("flume-session-{}.mcap", std::process::id()));
    let made = Command::new(env!("CARGO_BIN_EXE_flume-twin"))
        .current_dir(repo_file(""))
        .args(["make-session", "launch_configs/ulbra_flume.yaml", "--out"])
        .arg(&out)
        .output()
        .expect("runs the binary");
    assert!(made.status.success(), "{}", printed(&made));
    assert!(
        printed(&made).contains("2404 messages over 75 s"),
        "{}",
        printed(&made)
    );
    let (remade, bundled) = (
        std::fs::read(&out).expect("made"),
        std::fs::read(session()).expect("bundled"),
    );
    assert!(
        remade == bundled,
        "make-session no longer makes the bundled session"
    );
    std::fs::remove_file(&out).ok();
}

/// `--start-s` starts later with the discharge then in force (2.5 m3/h from 40 s), and
/// `--topics` replays only the topics named, saying which it passed over.
#[test]
fn a_replay_can_start_later_on_chosen_topics() {
    let Some(_gpu) = gpu() else { return };
    let csv = std::env::temp_dir().join(format!("flume-replay-start-{}", std::process::id()));
    let (ok, log) = replay(
        &session(),
        &[
            "--start-s",
            "45",
            "--topics",
            "/inflow,/gauges/p1",
            "--until",
            "0.2",
            "--csv",
            csv.to_str().expect("utf-8"),
        ],
    );
    assert!(ok, "{log}");
    assert!(
        log.contains("not replayed: /gauges/p2") && log.contains("not replayed: /gauges/p3"),
        "{log}"
    );
    assert!(log.contains("replayed 0.200 s"), "{log}");
    let rows = csv_rows(&csv.join("eroded_mass.csv"));
    let q: f64 = rows[1]["inflow_m3_per_s"].parse().expect("q");
    // The flow meter's 1 % noise: four sigmas.
    let due = 2.5 / 3600.0;
    assert!(
        (q - due).abs() < 0.04 * due,
        "the inlet ran {q} m3/s, not 2.5 m3/h"
    );
    let gauges = csv_rows(&csv.join("gauges.csv"));
    assert_eq!(gauges.len(), 3, "t = 0, 0.1 and 0.2 s");
    std::fs::remove_dir_all(&csv).ok();
}
