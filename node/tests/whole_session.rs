//! The bundled session (`tests/data/ulbra_session.mcap`, 75 s: 2 m3/h, then 2.5 m3/h from
//! t = 40 s) replayed in-process at CI size to its end: about 3.5 minutes on two cores, on the
//! CPU backend.

mod common;

use common::{ULBRA_CI, csv_rows, python_has, read_mcap, repo_file};
use serde_json::Value;
use std::process::Command;

/// Last sample of the session, s after its first.
const SESSION_S: f64 = 75.0;
/// Each predicted level against the measured one from [`STEADY_FROM_S`] on, while the flume
/// still fills as well, m: 1.5 dp. The session's "measurements" are the 1-D reference of
/// `flume_solver::hydraulics`. The case's own choices (DBC walls, alpha = 0.02, the release at
/// once) stood 2-3 cm over and rose to the end, and fail it.
const LEVEL_TOLERANCE_M: f64 = 0.015;
/// RMS of each gauge's residual once the flume has filled ([`FILLED_FROM_S`]), m: the levels
/// issue's goal. Measured with the twin's bed worn net of what settles (`van_rijn_exner`) and
/// the Shields test on the water's own speed: 1.9 / 0.9 / 2.0 mm at P1 / P2 / P3; the pick-up
/// worn away alone (`van_rijn_integrated`) gave 1.2 / 1.3 / 2.6 mm. The chance pick-up
/// (`van_rijn_pickup`, relative to the grain), which pulled whole particles out of the bed
/// under the front and left it a dp rough, gave 7.9 / 4.6 / 5.9 mm, and fails it.
const RMS_TOLERANCE_M: f64 = 0.003;
/// The residual's mean over the session's last 20 s against its mean over 20-40 s, m. The
/// discharge steps from 2 to 2.5 m3/h at 38 s, between the two, so this measures the twin's
/// rise against the reference's as well as a drift. The bound is the levels issue's goal, a
/// drift of 1 mm per 10 s over the 35 s between the windows' centres. Measured here: -2.2 /
/// -1.2 / -0.8 mm (`van_rijn_integrated`: -1.4 / -1.8 / -2.5 mm; the chance pick-up: 0.6 /
/// 1.4 / 2.1 mm).
const DRIFT_TOLERANCE_M: f64 = 0.0035;
/// From when the levels are compared: the front passed P3 by 6 s at CI size, plus 4 s.
const STEADY_FROM_S: f64 = 10.0;
/// From when the flume has filled and the RMS and the drift are taken.
const FILLED_FROM_S: f64 = 20.0;

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
    let mut residuals: Vec<(f64, [f64; 3])> = Vec::new();
    for m in messages
        .iter()
        .filter(|m| m["topic"] == "/gauges/predicted")
    {
        let stamp = &m["msg"]["header"]["stamp"];
        let t = num(&stamp["sec"]) - t0 + num(&stamp["nanosec"]) * 1e-9;
        if t < STEADY_FROM_S {
            continue;
        }
        let gauges = m["msg"]["gauges"].as_array().expect("gauges");
        assert_eq!(gauges.len(), 3, "P1, P2 and P3 at {t:.1} s");
        let mut r = [0.0; 3];
        for (g, r) in gauges.iter().zip(&mut r) {
            let (p, meas) = (num(&g["predicted_m"]), num(&g["measured_m"]));
            *r = p - meas;
            assert!(
                r.abs() <= LEVEL_TOLERANCE_M,
                "{} at {t:.1} s: predicted {p} against measured {meas}",
                g["name"]
            );
        }
        residuals.push((t, r));
    }
    assert!(
        residuals.len() > 500,
        "only {} samples compared",
        residuals.len()
    );
    levels_hold_without_drift(&residuals);
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
    // The eroded mass is the sand gone from the bed: collected whole, or worn off it as bed
    // load and passed into the pit or carried by grains let go (`van_rijn_exner`). It never
    // falls: a grain's wear leaves the books only as the grain is collected.
    for pair in rows.windows(2) {
        let ((t0, m0), (t1, m1)) = (pair[0], pair[1]);
        assert!(
            m1 >= m0 - 1e-9,
            "the eroded mass fell from {m0} to {m1} kg/m, {t0}-{t1} s"
        );
    }
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
/// the bit, and sand did leave the bed: at CI size 0.47 kg/m by 5 s and 2.5 kg/m by the end
/// (5 grains collected whole, 4.1 grains' mass worn off the bed), so the comparison is not one
/// of zeros.
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

/// The residuals (t, P1-P3) once the flume has filled: each gauge's RMS within
/// [`RMS_TOLERANCE_M`], and its mean over the last 20 s within [`DRIFT_TOLERANCE_M`] of its
/// mean over 20-40 s.
fn levels_hold_without_drift(residuals: &[(f64, [f64; 3])]) {
    let mean = |from: f64, to: f64, k: usize, f: &dyn Fn(f64) -> f64| -> f64 {
        let picked: Vec<f64> = residuals
            .iter()
            .filter(|(t, _)| (from..=to).contains(t))
            .map(|(_, r)| f(r[k]))
            .collect();
        assert!(!picked.is_empty(), "no sample from {from} to {to} s");
        picked.iter().sum::<f64>() / picked.len() as f64
    };
    for (k, name) in ["P1", "P2", "P3"].iter().enumerate() {
        let rms = mean(FILLED_FROM_S, SESSION_S, k, &|r| r * r).sqrt();
        let (early, late) = (
            mean(FILLED_FROM_S, 40.0, k, &|r| r),
            mean(SESSION_S - 20.0, SESSION_S, k, &|r| r),
        );
        eprintln!(
            "{name}: RMS {:.1} mm from {FILLED_FROM_S} s; mean {:.1} mm over 20-40 s, {:.1} mm over the last 20 s",
            rms * 1e3,
            early * 1e3,
            late * 1e3
        );
        assert!(rms <= RMS_TOLERANCE_M, "{name}: RMS {rms:.4} m");
        assert!(
            (late - early).abs() <= DRIFT_TOLERANCE_M,
            "{name} drifts: {early:.4} m, then {late:.4} m"
        );
    }
}
