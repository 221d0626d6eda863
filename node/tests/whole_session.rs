//! The bundled session (`tests/data/ulbra_session.mcap`, 75 s: 2 m3/h, then 2.5 m3/h from
//! t = 40 s) replayed in-process at CI size to its end: about 7.5 minutes on two cores, on the
//! CPU backend (18 on lavapipe).

mod common;

use common::{ULBRA_CI, csv_rows, python_has, read_mcap, repo_file};
use serde_json::Value;
use std::process::Command;

/// Last sample of the session, s after its first.
const SESSION_S: f64 = 75.0;
/// Predicted against measured level at P2 and P3 once the flow is steady: 3.5 dp. Set after
/// seeing the twin's levels at this resolution: they rise for about 40 s and settle 2 to 3 cm
/// above the session's (0.103 m at P2 against 0.0793 m at 2 m3/h, 0.112 against 0.0823 m at
/// 2.5 m3/h at the end, since the session is made by the 1-D reference of
/// `flume_solver::hydraulics`), where the solver's 18 s test still holds 1.5 dp. The flow is
/// two to four particles deep, and the water rides about a particle above the held bed and the
/// weir's crest (DBC's gap), so the CI-size twin stores more water than the 1-D friction law of
/// the session's model. This bound catches a level that drifts without end, not that bias. It
/// was 3 dp until the reference took the current carried over the short collector pit, which
/// lowered the session's levels by 1-2 mm: P2 then stood 3.02 cm over the session at 73 s.
/// The case's own levels are the open part of the levels work (README, levels section).
const LEVEL_TOLERANCE_M: f64 = 0.035;
/// From when the levels are compared: the front passed P3 by 6 s at CI size, plus 4 s.
const STEADY_FROM_S: f64 = 10.0;

#[test]
fn the_bundled_session_replays_to_its_end() {
    if !python_has("mcap_ros2", "mcap mcap-ros2-support") {
        return;
    }
    let dir = std::env::temp_dir().join(format!("flume-session-{}", std::process::id()));
    let (csv, twin) = (dir.join("csv"), dir.join("twin.mcap"));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let out = Command::new(env!("CARGO_BIN_EXE_flume-twin"))
        .arg("replay")
        .arg(repo_file("tests/data/ulbra_session.mcap"))
        .arg("--config")
        .arg(repo_file("launch_configs/ulbra_flume.yaml"))
        .args(ULBRA_CI)
        .args(["--csv", csv.to_str().expect("utf-8")])
        .args(["--out", twin.to_str().expect("utf-8")])
        .output()
        .expect("runs the binary");
    let log = common::printed(&out);
    eprintln!("{log}");
    assert!(out.status.success(), "the replay failed:\n{log}");
    assert!(
        log.contains(&format!("replayed {SESSION_S:.3} s")),
        "not to the end: {log}"
    );

    let gauges = csv_rows(&csv.join("gauges.csv"));
    let last_t: f64 = gauges.last().expect("rows")["time_s"].parse().expect("t");
    assert!(
        (last_t - SESSION_S).abs() < 1e-6,
        "gauges end at {last_t} s"
    );
    // Predicted against measured, as the twin published them on /gauges/predicted.
    let num = |v: &Value| v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"));
    let got = read_mcap(&twin, &["/gauges/predicted"]);
    assert!(got["error"].is_null(), "{}", got["error"]);
    let messages = got["messages"].as_array().expect("messages");
    let t0 = messages
        .first()
        .map(|m| num(&m["msg"]["header"]["stamp"]["sec"]))
        .expect("outputs");
    let mut compared = 0;
    let mut worst = 0.0f64;
    for m in messages
        .iter()
        .filter(|m| m["topic"] == "/gauges/predicted")
    {
        let stamp = &m["msg"]["header"]["stamp"];
        let t = num(&stamp["sec"]) - t0 + num(&stamp["nanosec"]) * 1e-9;
        if t < STEADY_FROM_S {
            continue;
        }
        for g in &m["msg"]["gauges"].as_array().expect("gauges")[1..] {
            let (p, meas) = (num(&g["predicted_m"]), num(&g["measured_m"]));
            assert!(
                (p - meas).abs() <= LEVEL_TOLERANCE_M,
                "{} at {t:.1} s: predicted {p} against measured {meas}",
                g["name"]
            );
            compared += 1;
            worst = worst.max((p - meas).abs());
        }
    }
    eprintln!("{compared} levels compared at P2 and P3 from {STEADY_FROM_S} s: worst {worst:.4} m");
    assert!(compared > 1000, "only {compared} levels compared");

    // The eroded mass stays finite and its rate bounded: at most 0.3 kg/m per second, the
    // top of the paper's Figure 10 (3 kg/m at 18 s) eroded in 10 s, over any 10 s. Over one
    // row (0.1 s) a single collected particle, 0.271 kg/m at dp = 1 cm, is 2.7 kg/m per
    // second: the rate is only measurable over many rows.
    let eroded = csv_rows(&csv.join("eroded_mass.csv"));
    let kg_per_m = |r: &std::collections::BTreeMap<String, String>| -> (f64, f64) {
        (
            r["time_s"].parse().expect("t"),
            r["eroded_kg_per_m"].parse().expect("kg/m"),
        )
    };
    let rows: Vec<(f64, f64)> = eroded.iter().map(kg_per_m).collect();
    assert!(rows.iter().all(|(_, m)| m.is_finite()), "a non-finite mass");
    let window_s = 10.0;
    for (k, &(t0, m0)) in rows.iter().enumerate() {
        let Some(&(t1, m1)) = rows[k..].iter().find(|(t, _)| *t >= t0 + window_s - 1e-9) else {
            break;
        };
        if t0 >= STEADY_FROM_S {
            assert!(
                m1 - m0 <= 0.3 * (t1 - t0),
                "{} kg/m eroded from {t0} to {t1} s",
                m1 - m0
            );
        }
    }
    published_eroded_mass_is_the_solver_s(&twin, &eroded);
    std::fs::remove_dir_all(&dir).ok();
}

/// Each eroded mass the twin published is the solver's row at its time (eroded_mass.csv), to
/// the bit, and sand did reach the collector: at CI size the first particle arrives at about
/// 28 s and 1.08 kg/m by the end, so the comparison is not one of zeros.
fn published_eroded_mass_is_the_solver_s(
    twin: &std::path::Path,
    rows: &[std::collections::BTreeMap<String, String>],
) {
    let num = |v: &Value| v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"));
    let got = read_mcap(twin, &["/eroded_mass"]);
    let published: Vec<&Value> = got["messages"]
        .as_array()
        .expect("messages")
        .iter()
        .filter(|m| m["topic"] == "/eroded_mass")
        .map(|m| &m["msg"])
        .collect();
    assert_eq!(published.len(), rows.len(), "one message per row");
    let secs = |m: &Value| {
        num(&m["header"]["stamp"]["sec"]) + num(&m["header"]["stamp"]["nanosec"]) * 1e-9
    };
    let time =
        |r: &std::collections::BTreeMap<String, String>| -> f64 { r["time_s"].parse().expect("t") };
    let (t0, row_t0) = (secs(published[0]), time(&rows[0]));
    for (m, row) in published.iter().zip(rows) {
        let t = time(row);
        assert!(
            ((secs(m) - t0) - (t - row_t0)).abs() < 1e-6,
            "stamp of the row at {t} s"
        );
        for (field, column) in [
            ("eroded_kg_per_m", "eroded_kg_per_m"),
            ("particles", "eroded_particles"),
        ] {
            let csv_value: f64 = row[column].parse().expect("a number");
            assert_eq!(num(&m[field]), csv_value, "{field} at {t} s");
        }
    }
    let last = num(&published.last().expect("messages")["eroded_kg_per_m"]);
    assert!(last > 0.0, "no sand reached the collector in the session");
}
