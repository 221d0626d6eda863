//! `flume-twin sweep` as a user runs it: a two-value roughness ladder on a short open flume,
//! and malformed ladders refused before anything runs or is written.

mod common;

use common::{csv_rows, repo_file};
use flume_solver::Case;
use std::fs;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const BIN: &str = env!("CARGO_BIN_EXE_flume-twin");

/// The short open flume: sand sinks into its collector within a few tenths of a second.
const CASE: &str = "solver/tests/cases/collector_2d.yaml";
/// Its sand is phase 1.
const KEY: &str = "phases.1.sediment.ks_over_d50";

/// A fresh, empty directory for one test's files.
fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("sweep")
        .join(name);
    let _ = fs::remove_dir_all(&dir);
    fs::create_dir_all(&dir).unwrap();
    dir
}

fn sweep(case: &str, ladder: &str, out_dir: &Path, more: &[&str]) -> Output {
    Command::new(BIN)
        .arg("sweep")
        .arg(repo_file(case))
        .args(["--set-values", ladder, "--out", out_dir.to_str().unwrap()])
        .args(more)
        .output()
        .unwrap()
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// Two roughnesses, given out of order: a row each in that order, each run to the end, with the
/// eroded mass of Eq. 34 (particles times dp^2 rho_s, per metre), the chart, and the table;
/// each run the one `simulate` gives with that value.
#[test]
fn a_roughness_ladder_gives_a_row_per_value_in_order() {
    let dir = scratch("ladder");
    let out_dir = dir.join("out");
    let out = sweep(CASE, &format!("{KEY}=7,1"), &out_dir, &["--until", "0.3"]);
    let stdout = text(&out.stdout);
    assert!(
        out.status.success(),
        "sweep failed: {}\n{stdout}",
        text(&out.stderr)
    );

    let case = Case::from_path(&repo_file(CASE)).unwrap();
    let dp = case.numerics.dp_m;
    let rho_s = case.phases[1].rho0_kg_per_m3;
    let width = case.open_flume.as_ref().unwrap().width_m;
    let rows = csv_rows(&out_dir.join("sweep.csv"));
    let values: Vec<&str> = rows.iter().map(|r| r[KEY].as_str()).collect();
    assert_eq!(values, ["7", "1"], "{rows:?}");
    let mut collected = 0;
    for r in &rows {
        assert_eq!(r["status"], "ok", "{r:?}");
        assert_eq!(r["time_s"].parse::<f64>().unwrap(), 0.3, "{r:?}");
        let kg_per_m: f64 = r["eroded_kg_per_m"].parse().unwrap();
        let kg: f64 = r["eroded_kg"].parse().unwrap();
        let particles: u64 = r["eroded_particles"].parse().unwrap();
        assert!(kg_per_m.is_finite() && kg_per_m >= 0.0, "{r:?}");
        let eq34 = particles as f64 * dp * dp * rho_s;
        assert!(
            (kg_per_m - eq34).abs() <= 1e-9 * eq34.max(1.0),
            "{kg_per_m} kg/m is not {particles} x dp^2 rho_s = {eq34}"
        );
        assert!((kg - kg_per_m * width).abs() <= 1e-9 * kg.max(1.0), "{r:?}");
        collected += particles;
    }
    // Each run is the run `simulate` gives for the case with that value: as many steps and the
    // same sand collected (runs are bit-identical on one backend and thread count).
    for r in &rows {
        let alone = dir.join(format!("simulate_{}", r[KEY]));
        let set = format!("{KEY}={}", r[KEY]);
        let out = Command::new(BIN)
            .arg("simulate")
            .arg(repo_file(CASE))
            .args(["--set", &set, "--until", "0.3", "--no-snapshots", "--out"])
            .arg(&alone)
            .output()
            .unwrap();
        assert!(out.status.success(), "{}", text(&out.stderr));
        let gauges = csv_rows(&alone.join("gauges.csv"));
        let eroded = csv_rows(&alone.join("eroded_mass.csv"));
        let (g, e) = (gauges.last().unwrap(), eroded.last().unwrap());
        assert_eq!(r["steps"], g["step"], "{set}: sweep {r:?}, simulate {g:?}");
        assert_eq!(r["eroded_particles"], e["eroded_particles"], "{set}");
        // The run's own files are simulate's, its sediment budget included, and the table's
        // budget columns are the budget's last row.
        let k = values.iter().position(|v| *v == r[KEY]).unwrap();
        let run_dir = out_dir.join(format!("{:02}_{}", k + 1, r[KEY]));
        for name in ["sediment_budget.csv", "eroded_mass.csv", "gauges.csv"] {
            let ours = fs::read_to_string(run_dir.join(name)).unwrap();
            let theirs = fs::read_to_string(alone.join(name)).unwrap();
            assert_eq!(ours, theirs, "{set}: {name}");
        }
        let budget = csv_rows(&run_dir.join("sediment_budget.csv"));
        let b = budget.last().unwrap();
        let t: f64 = b["time_s"].parse().unwrap();
        assert!((t - 0.3).abs() < 1e-9, "{set}: {b:?}");
        for (table, books) in [
            ("mobilised", "mobilised"),
            ("travelled_far", "travelled_far"),
            ("furthest_m", "furthest_m"),
            ("eroded_particles", "collected"),
        ] {
            assert_eq!(r[table], b[books], "{set}: {table}");
        }
    }
    // Without collected sand the mass check above would hold for any particle mass.
    assert!(collected > 0, "no sand reached the collector: {rows:?}");

    let png = fs::read(out_dir.join("sweep.png")).unwrap();
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");

    // The table: a line per value, first cell the value, ending in its status.
    for value in ["7", "1"] {
        assert!(
            stdout.lines().any(|l| {
                l.split_whitespace().next() == Some(value) && l.trim_end().ends_with("ok")
            }),
            "no table row for {value}:\n{stdout}"
        );
    }
}

/// The first line naming the backend ("adapter: ...") in a command's output.
fn adapter_line(stdout: &str) -> Option<String> {
    stdout
        .lines()
        .find(|l| l.starts_with("adapter: "))
        .map(str::to_string)
}

/// `sweep` runs on the backend `simulate` chooses, on whatever machine this is and with the
/// backend named (`FLUME_TWIN_ADAPTER=cpu`): a sweep that opened the GPU itself ran on lavapipe,
/// six times slower than `simulate` on a machine without a hardware GPU.
#[test]
fn sweep_runs_on_the_backend_simulate_chooses() {
    for wanted in [None, Some("cpu")] {
        let dir = scratch(&format!("backend_{}", wanted.unwrap_or("default")));
        let with_env = |c: &mut Command| {
            if let Some(w) = wanted {
                c.env("FLUME_TWIN_ADAPTER", w);
            } else {
                c.env_remove("FLUME_TWIN_ADAPTER");
            }
        };
        let mut simulate = Command::new(BIN);
        simulate
            .arg("simulate")
            .arg(repo_file(CASE))
            .args(["--until", "0.01", "--no-snapshots", "--out"])
            .arg(dir.join("simulate"));
        with_env(&mut simulate);
        let simulated = simulate.output().unwrap();
        assert!(simulated.status.success(), "{}", text(&simulated.stderr));
        let mut sweep = Command::new(BIN);
        sweep
            .arg("sweep")
            .arg(repo_file(CASE))
            .args([
                "--set-values",
                &format!("{KEY}=3"),
                "--until",
                "0.01",
                "--out",
            ])
            .arg(dir.join("sweep"));
        with_env(&mut sweep);
        let swept = sweep.output().unwrap();
        assert!(swept.status.success(), "{}", text(&swept.stderr));
        let (a, b) = (
            adapter_line(&text(&simulated.stdout)),
            adapter_line(&text(&swept.stdout)),
        );
        assert!(a.is_some(), "simulate named no backend");
        assert_eq!(a, b, "FLUME_TWIN_ADAPTER={wanted:?}");
        if wanted == Some("cpu") {
            assert!(
                b.is_some_and(|l| l.contains("CPU")),
                "FLUME_TWIN_ADAPTER=cpu"
            );
        }
    }
}

/// Each malformed ladder fails with its reason before a backend is opened or anything is
/// written. In the non-number case the bad value is the second one: a sweep that ran values
/// as it read them would open a backend for the first.
#[test]
fn malformed_ladders_are_refused_before_any_run() {
    let dir = scratch("malformed");
    let out_dir = dir.join("out");
    let flag = format!("{KEY}=5");
    // (case, ladder, further arguments, what the error must say)
    let refusals: [(&str, String, &[&str], &[&str]); 7] = [
        (CASE, KEY.to_string(), &[], &["has no '='"]),
        (CASE, format!("{KEY}="), &[], &["lists no values"]),
        (
            CASE,
            format!("{KEY}=3,rough"),
            &[],
            &["phases[1].sediment.ks_over_d50", "rough"],
        ),
        (
            CASE,
            "phases.1.sediment.bogus_knob=1,2".to_string(),
            &[],
            &["phases[1].sediment.bogus_knob"],
        ),
        (
            "launch_configs/dambreak_water.yaml",
            "numerics.cfl=0.2,0.1".to_string(),
            &[],
            &["sweep needs an open flume"],
        ),
        (
            CASE,
            format!("{KEY}=1,2"),
            &["--until", "-1"],
            &["--until", "positive"],
        ),
        (CASE, format!("{KEY}=1,2"), &["--set", &flag], &["both set"]),
    ];
    for (case, ladder, more, expected) in &refusals {
        let out = sweep(case, ladder, &out_dir, more);
        let stderr = text(&out.stderr);
        assert!(!out.status.success(), "{ladder} {more:?} was accepted");
        for word in expected.iter() {
            assert!(
                stderr.contains(word),
                "{ladder} {more:?}: no {word:?} in: {stderr}"
            );
        }
        assert!(
            !text(&out.stdout).contains("adapter:"),
            "{ladder} {more:?} opened a backend first"
        );
        assert!(
            !out_dir.exists(),
            "{ladder} {more:?} created the output directory"
        );
    }
}
