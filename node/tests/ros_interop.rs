//! The twin as a ROS 2 node against a DDS nobody here wrote: a Python peer on Cyclone DDS
//! (`tests/interop/dds_peer.py`) plays the sensors over loopback and records what the twin
//! publishes; the values it receives must be the ones the solver produced (the node's own
//! `--out` CSV files), and the bad samples it slips in must be refused and counted.

mod common;

use common::{csv_rows, gpu, python_has, recycle_twin, repo_file};
use serde_json::Value;
use std::collections::BTreeMap;
use std::process::{Command, Stdio};

fn num(v: &Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}

#[test]
fn a_cyclone_dds_peer_drives_the_twin_and_reads_the_solver_s_outputs() {
    let Some(_gpu) = gpu() else { return };
    if !python_has("cyclonedds", "cyclonedds") {
        return;
    }
    let dir = std::env::temp_dir().join(format!("flume-ros-interop-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let out_dir = dir.join("out");
    // The twin runs to 3 s of simulated time behind sensors that speak for 4 s; on a
    // software adapter it lags them, so its lag and decimation show in /diagnostics. Its
    // simulated time never passes the sensors', so it runs at least 3 s of wall time: the
    // peer's bad samples (at 1.3 s) reach a /diagnostics (1 Hz) before it ends. At 0.5 s a
    // twin that kept up ended before that, and the refusal counts were never seen.
    let node = recycle_twin()
        .args([
            "--wait-for-sensors",
            "--until",
            "3.0",
            "--out",
            out_dir.to_str().expect("utf-8"),
            "--ros-args",
            "-r",
            "__ns:=/flume_test",
            "-p",
            "publish_rate_hz:=20.0",
        ])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the twin starts");
    let peer = Command::new("python3")
        .arg(repo_file("tests/interop/dds_peer.py"))
        .args(["/flume_test", "4", "40"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the peer starts");
    let node = node.wait_with_output().expect("the twin ends");
    let node_log =
        String::from_utf8_lossy(&node.stdout).to_string() + &String::from_utf8_lossy(&node.stderr);
    assert!(node.status.success(), "the twin failed:\n{node_log}");
    assert!(node_log.contains("reached t = 3.000 s"), "{node_log}");
    // Once the twin is gone the peer has seen all it will: give the last samples a moment
    // in flight, then stop it.
    std::thread::sleep(std::time::Duration::from_secs(2));
    let mut peer = peer;
    let _ = peer.kill();
    let peer = peer.wait_with_output().expect("the peer ends");
    let peer_out = String::from_utf8_lossy(&peer.stdout).to_string();
    let peer_err = String::from_utf8_lossy(&peer.stderr).to_string();
    assert!(
        !peer_err.contains("Traceback"),
        "the peer failed: {peer_err}\n{peer_out}"
    );
    let particles = node_log
        .lines()
        .find_map(|l| l.strip_prefix("particles: "))
        .expect("a particles line")
        .to_string();
    let mut got: BTreeMap<String, Vec<Value>> = BTreeMap::new();
    for line in peer_out.lines() {
        let v: Value = serde_json::from_str(line).unwrap_or_else(|e| panic!("{line}: {e}"));
        let (k, body) = v
            .as_object()
            .and_then(|o| o.iter().next())
            .expect("one key");
        got.entry(k.clone()).or_default().push(body.clone());
    }
    let count = |k: &str| got.get(k).map_or(0, Vec::len);
    eprintln!(
        "peer: sent {}, received {} bed profiles, {} eroded masses, {} gauge comparisons, {} clouds, {} marker arrays, {} clocks, {} diagnostics",
        count("sent"),
        count("bed_profile"),
        count("eroded_mass"),
        count("predicted"),
        count("particles"),
        count("bed_marker"),
        count("clock"),
        count("diagnostics")
    );
    let matched = &got["matched"][0];
    assert!(
        num(&matched["inflow"]) >= 1.0 && num(&matched["p1"]) >= 1.0,
        "{matched}"
    );

    plots_hold_both_lines(&out_dir, &node_log);

    // The gauge comparison: predicted is the solver's P1 at that time (gauges.csv), measured
    // one of the levels the peer sent, residual their difference.
    let gauges = csv_rows(&out_dir.join("gauges.csv"));
    let comparisons = &got["predicted"];
    assert!(comparisons.len() >= 3, "{comparisons:?}");
    // Simulated time 0 in the sensors' clock: the stamps are origin + t.
    let t_first = num(&comparisons[0]["t"]);
    let origin_candidates: Vec<f64> = gauges
        .iter()
        .map(|r| t_first - r["time_s"].parse::<f64>().expect("time"))
        .collect();
    let mut checked = 0;
    for origin in origin_candidates {
        let all_match = comparisons.iter().all(|c| {
            let t = num(&c["t"]) - origin;
            gauges.iter().any(|r| {
                let (rt, p1): (f64, f64) = (
                    r["time_s"].parse().expect("time"),
                    r["P1_m"].parse().expect("level"),
                );
                (rt - t).abs() < 1e-6 && (p1 - num(&c["gauges"][0]["predicted"])).abs() < 1e-6
            })
        });
        if all_match {
            checked = comparisons.len();
            break;
        }
    }
    assert_eq!(
        checked,
        comparisons.len(),
        "a predicted level is not the solver's at its time"
    );
    // The measured level is the one in force at the comparison's time: the last level the
    // peer sent stamped at or before it. Levels go best effort and one may be lost, so any
    // of the last three sent by then passes; they cycle through five values, so a level sent
    // after that time, or long before, would not be among them.
    let sent: Vec<(f64, f64)> = got["sent"]
        .iter()
        .map(|s| (num(&s["t"]), num(&s["level"])))
        .collect();
    let mut measured_seen = 0;
    for c in comparisons {
        let g = &c["gauges"][0];
        assert_eq!(g["name"], "P1");
        if let Some(m) = g["measured"].as_f64() {
            measured_seen += 1;
            let t = num(&c["t"]);
            let in_force: Vec<f64> = sent
                .iter()
                .filter(|(stamp, _)| *stamp <= t + 1e-6)
                .rev()
                .take(3)
                .map(|s| s.1)
                .collect();
            assert!(
                in_force.contains(&m),
                "measured {m} at t = {t} is none of the levels in force then: {in_force:?}"
            );
            // The sign of the published residual: predicted minus measured.
            assert_eq!(num(&g["residual"]), num(&g["predicted"]) - m);
        }
    }
    assert!(measured_seen > 0, "no comparison carried a measurement");

    // The bed profile and eroded mass of the last output are the solver's last rows.
    let bed = csv_rows(&out_dir.join("bed_profile.csv"));
    let last_bed = got["bed_profile"].last().expect("a bed profile");
    let last_t: f64 = bed.last().expect("rows")["time_s"].parse().expect("time");
    let rows: Vec<_> = bed
        .iter()
        .filter(|r| r["time_s"].parse::<f64>().expect("time") == last_t)
        .collect();
    let xs: Vec<f64> = last_bed["x"]
        .as_array()
        .expect("x")
        .iter()
        .map(num)
        .collect();
    assert_eq!(xs.len(), rows.len());
    for (k, r) in rows.iter().enumerate() {
        assert!((xs[k] - r["x_m"].parse::<f64>().expect("x")).abs() < 1e-6);
        let zs: f64 = r["zs_m"].parse().expect("zs");
        assert!(
            (num(&last_bed["zs"][k]) - zs).abs() < 1e-6,
            "zs at {}",
            xs[k]
        );
    }
    let eroded = csv_rows(&out_dir.join("eroded_mass.csv"));
    let last_eroded = got["eroded_mass"].last().expect("an eroded mass");
    let csv_kg: f64 = eroded.last().expect("rows")["eroded_kg"]
        .parse()
        .expect("kg");
    assert!((num(&last_eroded["kg"]) - csv_kg).abs() < 1e-9 * csv_kg.max(1.0));
    let kgs: Vec<f64> = got["eroded_mass"].iter().map(|e| num(&e["kg"])).collect();
    assert!(
        kgs.windows(2).all(|w| w[1] >= w[0]),
        "eroded mass went down: {kgs:?}"
    );

    // The particle cloud: x, y, z, speed (float32) and phase (uint8) of every particle in the
    // flow (walls, water, sand; the parked ones left out), finite; the bed and water lines.
    let cloud = got["particles"].last().expect("a particle cloud");
    assert_eq!(
        cloud["fields"],
        serde_json::json!([
            ["x", 0, 7],
            ["y", 4, 7],
            ["z", 8, 7],
            ["speed", 12, 7],
            ["phase", 16, 2]
        ])
    );
    let width = num(&cloud["width"]);
    assert!(
        width > 0.0 && width <= particles.parse::<f64>().expect("count"),
        "{cloud}"
    );
    assert_eq!(cloud["finite"], true);
    assert_eq!(
        cloud["phases"],
        serde_json::json!([0, 1, 2]),
        "walls, water, sand"
    );
    let markers = &got["bed_marker"].last().expect("bed lines")["markers"];
    assert_eq!(markers[0]["ns"], "bed");
    assert_eq!(markers[1]["ns"], "water");
    assert_eq!(markers[0]["type"], 4, "LINE_STRIP");
    assert!(num(&markers[1]["points"]) >= 1.0);

    // /clock runs forward; /diagnostics counts the refused samples by reason.
    let clocks: Vec<f64> = got["clock"].iter().map(|c| num(&c["t"])).collect();
    assert!(clocks.windows(2).all(|w| w[1] > w[0]), "{clocks:?}");
    let diag = got["diagnostics"]
        .iter()
        .rfind(|d| d["status"][0]["name"] == "/flume_test/flume_twin: twin")
        .expect("this twin's diagnostics, named after its node");
    let values = &diag["status"][0]["values"];
    for (key, want) in [
        ("non_finite", "1"),
        ("negative_discharge", "1"),
        ("level_outside_flume", "1"),
        ("future_stamp", "1"),
        ("out_of_order", "1"),
        ("rejected_inputs", "5"),
        ("particles", particles.as_str()),
    ] {
        assert_eq!(values[key], want, "{key} in {values}");
    }
    for key in [
        "real_time_factor",
        "lag_s",
        "step_rate_hz",
        "adapter",
        "stale_sensors",
        "inlet_blocked_spots",
        "bed_pores_particles",
    ] {
        assert!(values.get(key).is_some(), "no {key} in {values}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// At --until the twin drew its plots beside the CSV files: gauges.png with the levels the
/// peer sent (the measured line's colour in `series_plot.rs`) beside its own (the predicted
/// line's), and below them the residuals (P1's residual colour). A plot of the solver's
/// levels alone, one without the residual panel, or none, fails.
fn plots_hold_both_lines(out_dir: &std::path::Path, node_log: &str) {
    for name in ["gauges.png", "eroded_mass.png"] {
        let path = out_dir.join(name);
        assert!(
            node_log.contains(&format!("plot: {}", path.display())),
            "{name} not drawn:\n{node_log}"
        );
    }
    let decoder =
        png::Decoder::new(std::fs::File::open(out_dir.join("gauges.png")).expect("opens"));
    let mut reader = decoder.read_info().expect("a PNG");
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).expect("decodes");
    assert_eq!(info.color_type, png::ColorType::Rgb);
    let pixels_near = |colour: [u8; 3]| {
        buf[..info.buffer_size()]
            .chunks_exact(3)
            .filter(|p| p.iter().zip(colour).all(|(a, b)| a.abs_diff(b) < 40))
            .count()
    };
    let predicted = pixels_near([40, 90, 200]);
    let measured = pixels_near([200, 80, 40]);
    let residual = pixels_near([0, 160, 190]);
    eprintln!(
        "gauges.png: {predicted} pixels of the predicted lines, {measured} of the measured, {residual} of P1's residual"
    );
    assert!(
        predicted > 200 && measured > 200 && residual > 200,
        "predicted {predicted}, measured {measured}, residual {residual} pixels"
    );
}
