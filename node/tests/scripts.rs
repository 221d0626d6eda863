//! The helper scripts under `scripts/` that make the docs' figures, on inputs written by hand.

mod common;

use common::repo_file;
use std::process::Command;
use std::time::{Duration, Instant};

/// `water_front.py` on two runs' bed profiles: the front is the furthest column with water at
/// least 4 mm over the sand, or over the bed's first top where a column holds no sand (the
/// pit), and never a column where the water is thinner than that or the sand is wet by nothing.
#[test]
fn water_front_finds_the_furthest_column_with_water_over_the_bed() {
    let dir = std::env::temp_dir().join(format!("flume-front-{}", std::process::id()));
    let (a, b) = (dir.join("a"), dir.join("b"));
    std::fs::create_dir_all(&a).expect("dir a");
    std::fs::create_dir_all(&b).expect("dir b");
    // Run a: at 0 s dry (the bed's top 0.055); at 1 s 10 mm of water at 0.1 and 3 mm (too
    // thin) at 0.2; at 2 s water 5 mm over a pit column with no sand at 0.3, though only 2 mm
    // over the scoured sand at 0.2 (the water is measured from the bed's first top).
    std::fs::write(
        a.join("bed_profile.csv"),
        "time_s,x_m,zb_m,zs_m,zw_m\n\
         0,0.1,,0.055,0.055\n0,0.2,,0.055,0.055\n0,0.3,,,0\n\
         1,0.1,,0.055,0.065\n1,0.2,,0.055,0.058\n1,0.3,,,0\n\
         2,0.1,,0.055,0.070\n2,0.2,,0.050,0.057\n2,0.3,,,0.060\n",
    )
    .expect("profile a");
    // Run b: 5 mm of water over sand piled above the first top (0.060) is not enough there.
    std::fs::write(
        b.join("bed_profile.csv"),
        "time_s,x_m,zb_m,zs_m,zw_m\n\
         0,0.1,,0.055,0.055\n0,0.2,,0.055,0.055\n\
         1,0.1,,0.055,0.060\n1,0.2,,0.060,0.063\n",
    )
    .expect("profile b");
    let out = Command::new("python3")
        .arg(repo_file("scripts/water_front.py"))
        .arg(&a)
        .arg(&b)
        .output()
        .expect("python3 runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    let rows: Vec<&str> = text.lines().skip(1).collect();
    assert_eq!(rows, ["0.0,,", "1.0,0.100,0.100", "2.0,0.300,"], "{text}");
    std::fs::remove_dir_all(&dir).ok();
}

/// A run directory without a bed profile, or a file that is not one, is refused by name.
#[test]
fn water_front_names_what_it_cannot_read() {
    let dir = std::env::temp_dir().join(format!("flume-front-bad-{}", std::process::id()));
    let bad = dir.join("bad");
    std::fs::create_dir_all(&bad).expect("dir");
    std::fs::write(bad.join("bed_profile.csv"), "time_s,x_m\n0,zero\n").expect("file");
    let run = |arg: &std::path::Path| {
        Command::new("python3")
            .arg(repo_file("scripts/water_front.py"))
            .arg(arg)
            .output()
            .expect("python3 runs")
    };
    for (arg, says) in [
        (dir.join("missing"), "cannot read"),
        (bad.clone(), "not a bed profile"),
    ] {
        let out = run(&arg);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{} was read", arg.display());
        assert!(
            err.contains(says) && err.contains("bed_profile.csv"),
            "{err}"
        );
        assert!(!err.contains("Traceback"), "{err}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// `bed_load.py` against Meyer-Peter & Mueller worked by hand. 2 m3/h over 86 mm (q =
/// 6.460e-3 m2/s) 25 mm deep over sand of d50 = 0.4 mm, ks = 1.2 mm: U = 0.2584 m/s,
/// ln(11 h / ks) = 5.4344, u* = 0.41 U / 5.4344 = 0.019495 m/s, theta = u*^2 / (1.71 g d50) =
/// 0.05664, q* = 8 (0.05664 - 0.047)^1.5 = 7.572e-3, times sqrt(1.71 g d50^3) = 3.2766e-5 m2/s
/// and 2,710 kg/m3: 6.723e-4 kg/m/s, 6.723e-3 kg/m over 10 s. A flow 40 mm deep (theta =
/// 0.0187) moves nothing. The run's own collected mass is read over the same span.
#[test]
fn bed_load_integrates_meyer_peter_mueller_on_the_runs_depths() {
    let dir = std::env::temp_dir().join(format!("flume-bedload-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("dir");
    // The bed's top at 0.055 m: 25 mm of water from 0 to 10 s, then 40 mm; dry before 0.
    std::fs::write(
        dir.join("gauges.csv"),
        "time_s,step,P3_m\n-1,0,0.055\n0,1,0.080\n5,2,0.080\n10,3,0.080\n15,4,0.095\n20,5,0.095\n",
    )
    .expect("gauges");
    std::fs::write(
        dir.join("eroded_mass.csv"),
        "time_s,eroded_kg_per_m\n0,0.1\n5,0.2\n10,0.3\n15,0.3\n20,0.5\n",
    )
    .expect("eroded");
    let out = Command::new("python3")
        .arg(repo_file("scripts/bed_load.py"))
        .arg(&dir)
        .args(["--gauge", "P3", "--bed-m", "0.055"])
        .output()
        .expect("python3 runs");
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(out.status.success(), "{err}");
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    let total = |t: &str| -> f64 {
        let row = text
            .lines()
            .find(|l| l.split(',').next() == Some(t))
            .unwrap_or_else(|| panic!("no row at {t} s:\n{text}"));
        row.split(',')
            .nth(4)
            .expect("mpm_kg_per_m")
            .parse()
            .expect("a number")
    };
    assert!((total("10") / 6.723e-3 - 1.0).abs() < 1e-3, "{text}");
    // From 10 to 15 s the rate falls to nothing: half a trapezoid, 5 s x 6.723e-4 / 2.
    assert!(
        (total("15") / (6.723e-3 + 1.681e-3) - 1.0).abs() < 1e-3,
        "{text}"
    );
    assert_eq!(total("15"), total("20"), "{text}");
    assert!(err.contains("the run collected 0.400 kg/m"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

/// A run directory without the gauge asked for, or without its files, is refused by name.
#[test]
fn bed_load_names_what_it_cannot_read() {
    let dir = std::env::temp_dir().join(format!("flume-bedload-bad-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("dir");
    std::fs::write(dir.join("gauges.csv"), "time_s,P1_m\n0,0.08\n").expect("gauges");
    std::fs::write(dir.join("eroded_mass.csv"), "time_s,eroded_kg_per_m\n0,0\n").expect("mass");
    let run = |dir: &std::path::Path| {
        Command::new("python3")
            .arg(repo_file("scripts/bed_load.py"))
            .arg(dir)
            .args(["--gauge", "P3", "--bed-m", "0.055"])
            .output()
            .expect("python3 runs")
    };
    let no_gauge = run(&dir);
    assert!(!no_gauge.status.success());
    assert!(
        String::from_utf8_lossy(&no_gauge.stderr).contains("no column ['P3_m']"),
        "{}",
        String::from_utf8_lossy(&no_gauge.stderr)
    );
    let missing = run(&dir.join("nowhere"));
    assert!(!missing.status.success());
    assert!(
        String::from_utf8_lossy(&missing.stderr).contains("cannot read"),
        "{}",
        String::from_utf8_lossy(&missing.stderr)
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// `figure10_chart.py` draws each ks/d50's mean as the bar and the runs' range as the whisker,
/// on the paper's axis to 3 kg/m unless a run goes over. By hand, for a plot 320 px high from
/// y = 40: runs of 0.5 and 1.0 kg/m give a bar to 0.75 (y = 40 + 320 (1 - 0.75 / 3) = 280.0)
/// and a whisker from 0.5 (306.7) to 1.0 (253.3); a run of 4.2 kg/m at ks/d50 = 3, left of the
/// legend, stretches the axis to 4.5. The bars of the legend's slots (from the fourth, or the
/// last of a shorter ladder) stay under it (24 + 16 px a row, one ladder and the aim: 56 px):
/// a run of 3 kg/m at ks/d50 = 7 needs 3 / (1 - 56 / 320) = 3.64, an axis to 4, and 4.2 kg/m
/// alone in the legend's slot 5.09, an axis to 5.5.
#[test]
fn figure10_chart_draws_the_mean_and_the_range_of_the_runs() {
    let dir = std::env::temp_dir().join(format!("flume-fig10-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("dir");
    let chart = |rows: &str| {
        let path = dir.join("runs.csv");
        std::fs::write(&path, format!("ks_over_d50,eroded_kg_per_m\n{rows}")).expect("csv");
        Command::new("python3")
            .arg(repo_file("scripts/figure10_chart.py"))
            .arg(format!("runs={}", path.display()))
            .output()
            .expect("python3 runs")
    };
    let out = chart("3,0.5\n3,1.0\n");
    let svg = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let bar = svg.lines().find(|l| l.contains("fill=\"#9e9e9e\"/>"));
    assert!(bar.is_some_and(|l| l.contains("y=\"280.0\"")), "{svg}");
    assert!(svg.contains("y1=\"306.7\" y2=\"253.3\""), "{svg}");
    assert!(!svg.contains(">3.5<"), "{svg}");
    let out = chart("3,4.2\n7,0.1\n");
    let svg = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(svg.contains(">4.5<") && !svg.contains(">5<"), "{svg}");
    let out = chart("3,4.2\n");
    let svg = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(svg.contains(">5.5<") && !svg.contains(">6<"), "{svg}");
    let out = chart("3,0.5\n7,3.0\n");
    let svg = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(svg.contains(">4<") && !svg.contains(">4.5<"), "{svg}");
    let out = chart("3,lots\n");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && err.contains("not a ladder of runs"),
        "{err}"
    );
    assert!(!err.contains("Traceback"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

/// `figure9_chart.py` draws each run of a front table as a line, leaving out the times it was
/// dry. By hand, for a plot 440 px wide from x = 70 and 320 px high from y = 40, to 8 s and
/// over the flume's 2.5 m: run a at (4 s, 1.25 m) and (8 s, 2.5 m) gives the points (290.0,
/// 200.0) and (510.0, 40.0); run b at (0 s, 0.1 m) and (8 s, 0.5 m) gives (70.0, 347.2) and
/// (510.0, 296.0). A run to 10 s stretches the axis to 10 s, its end then at x = 510.0.
#[test]
fn figure9_chart_draws_each_run_s_front_against_time() {
    let dir = std::env::temp_dir().join(format!("flume-fig9-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("dir");
    let chart = |table: &str| {
        let path = dir.join("front.csv");
        std::fs::write(&path, table).expect("csv");
        Command::new("python3")
            .arg(repo_file("scripts/figure9_chart.py"))
            .arg(format!("L={}", path.display()))
            .output()
            .expect("python3 runs")
    };
    let out = chart("time_s,front_m out/a,front_m out/b\n0,,0.1\n4,1.25,\n8,2.5,0.5\n");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let svg = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(svg.contains("points=\"290.0,200.0 510.0,40.0\""), "{svg}");
    assert!(svg.contains("points=\"70.0,347.2 510.0,296.0\""), "{svg}");
    assert!(svg.contains(">L, a<") && svg.contains(">L, b<"), "{svg}");
    assert!(!svg.contains(">9<"), "{svg}");
    let out = chart("time_s,front_m out/a\n0,0.5\n10,1.0\n");
    let svg = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(svg.contains(">10<"), "{svg}");
    assert!(svg.contains("points=\"70.0,296.0 510.0,232.0\""), "{svg}");
    let out = chart("ks_over_d50,eroded_kg_per_m\n3,0.5\n");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && err.contains("not a front table"),
        "{err}"
    );
    let out = chart("time_s,front_m out/a\nlate,0.5\n");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && err.contains("not a front table"),
        "{err}"
    );
    assert!(!err.contains("Traceback"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

/// A snapshot as the twin writes it (legacy binary VTK, big-endian) of `(x, y, u, phase)`
/// particles at rest density, at `t` s.
fn snapshot(t: f64, particles: &[(f32, f32, f32, i32)]) -> Vec<u8> {
    let n = particles.len();
    let mut b = format!(
        "# vtk DataFile Version 3.0\nflume-twin test t = {t} s step 0\nBINARY\n\
         DATASET UNSTRUCTURED_GRID\nPOINTS {n} float\n"
    )
    .into_bytes();
    for &(x, y, _, _) in particles {
        [x, y, 0.0].iter().for_each(|v| b.extend(v.to_be_bytes()));
    }
    b.extend(format!("\nCELLS {n} {}\n", 2 * n).bytes());
    for k in 0..n as i32 {
        [1, k].iter().for_each(|v| b.extend(v.to_be_bytes()));
    }
    b.extend(format!("\nCELL_TYPES {n}\n").bytes());
    (0..n).for_each(|_| b.extend(1i32.to_be_bytes()));
    b.extend(format!("\nPOINT_DATA {n}\nVECTORS velocity float\n").bytes());
    for &(_, _, u, _) in particles {
        [u, 0.0, 0.0].iter().for_each(|v| b.extend(v.to_be_bytes()));
    }
    b.extend(b"\nSCALARS density float 1\nLOOKUP_TABLE default\n");
    for &(_, _, _, phase) in particles {
        let rho: f32 = if phase == 2 { 2710.0 } else { 1000.0 };
        b.extend(rho.to_be_bytes());
    }
    b.extend(b"\nSCALARS phase int 1\nLOOKUP_TABLE default\n");
    particles.iter().for_each(|p| b.extend(p.3.to_be_bytes()));
    b.push(b'\n');
    b
}

/// `pit_current.py` on two snapshots written by hand, dp = 1 cm: water 8 rows deep (centres
/// 0.01-0.08 m) over x = 2.2-2.5 m, a weir of walls at x >= 2.49 m whose top particle is at
/// 0.050 m (crest 0.055 m). At 30 s the column [2.30, 2.32) carries u = 0.3 m/s in its top row
/// (25 mm over the crest), 0.2 in the row under it and -0.1 in its bottom row, two particles a
/// row: q = (0.6 + 0.4 - 0.2) 1e-4 / 0.02 = 4e-3 m2/s, 1e-3 of it back; its core is 25 mm
/// over the crest, two layers thick; its energy is the surface plus (2 0.3^3 + 2 0.2^3) /
/// (2 0.3 + 2 0.2) / 2 g = 3.57 mm. The column [2.32, 2.34) carries 0.3 m/s only at 0.02 m:
/// a plunged core, 35 mm under the crest. The surface of a full lattice lies about half a dp
/// over its top row: 30 mm over the crest. The snapshot at 10 s, all at rest, lies before
/// `--from-s` and must not count.
#[test]
fn pit_current_finds_the_core_of_the_current_and_its_energy() {
    let dir = std::env::temp_dir().join(format!("flume-pit-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("dir");
    let state = |moving: bool| {
        let mut p = Vec::new();
        for k in 0..4 {
            let x = 2.485 + 0.01 * k as f32;
            (0..6).for_each(|r| p.push((x + 0.005, 0.01 * r as f32, 0.0, 0)));
        }
        for c in 0..29 {
            let x = 2.205 + 0.01 * c as f32;
            for r in 0..8 {
                let y = 0.01 * (r + 1) as f32;
                let u = match (
                    moving,
                    (2.30..2.32).contains(&x),
                    (2.32..2.34).contains(&x),
                    r,
                ) {
                    (true, true, _, 7) => 0.3,
                    (true, true, _, 6) => 0.2,
                    (true, true, _, 0) => -0.1,
                    (true, _, true, 1) => 0.3,
                    _ => 0.0,
                };
                p.push((x, y, u, 1));
            }
        }
        p
    };
    std::fs::write(
        dir.join("particles_0000.vtk"),
        snapshot(10.0, &state(false)),
    )
    .expect("vtk");
    std::fs::write(dir.join("particles_0001.vtk"), snapshot(30.0, &state(true))).expect("vtk");
    let out = Command::new("python3")
        .arg(repo_file("scripts/pit_current.py"))
        .arg(&dir)
        .args([
            "--dp", "0.01", "--from-s", "20", "--x0", "2.3", "--x1", "2.34",
        ])
        .output()
        .expect("python3 runs");
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let rows: Vec<Vec<f64>> = (text.lines().skip(2))
        .map(|l| l.split(',').map(|v| v.parse().expect("a number")).collect())
        .collect();
    assert_eq!(rows.len(), 2, "{text}");
    let (a, b) = (&rows[0], &rows[1]);
    assert!((a[1] - 30.0).abs() < 1.0, "the surface: {text}");
    assert!(
        (a[2] - 4e-3).abs() < 1e-6 && (a[3] + 1e-3).abs() < 1e-6,
        "{text}"
    );
    assert!((a[4] - a[1] - 3.568).abs() < 0.02, "the energy: {text}");
    assert_eq!((a[5], a[6], a[7], a[8]), (25.0, 0.3, 20.0, 1.0), "{text}");
    assert_eq!((b[5], b[6], b[7]), (-35.0, 0.3, 10.0), "{text}");
    std::fs::remove_dir_all(&dir).ok();
}

/// A directory with no snapshot, or one that is not the twin's, is refused by name.
#[test]
fn pit_current_names_what_it_cannot_read() {
    let dir = std::env::temp_dir().join(format!("flume-pit-bad-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("dir");
    let run = || {
        Command::new("python3")
            .arg(repo_file("scripts/pit_current.py"))
            .arg(&dir)
            .args(["--dp", "0.01"])
            .output()
            .expect("python3 runs")
    };
    let out = run();
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(
        !out.status.success() && err.contains("no particles_*.vtk"),
        "{err}"
    );
    std::fs::write(
        dir.join("particles_0000.vtk"),
        "# vtk DataFile Version 3.0\nother\nASCII\n",
    )
    .expect("file");
    let out = run();
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(
        !out.status.success() && err.contains("particles_0000.vtk"),
        "{err}"
    );
    assert!(!err.contains("Traceback"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

/// One cargo message naming the test executable `dir/name` of `package`, from `tests/source`
/// (cargo's JSON layout).
fn test_artifact(dir: &std::path::Path, package: &str, name: &str, source: &str) -> String {
    serde_json::json!({
        "reason": "compiler-artifact",
        "package_id": format!("path+file://{}#{package}@0.1.0", dir.display()),
        "manifest_path": dir.join("Cargo.toml"),
        "target": {"name": name, "kind": ["test"], "src_path": dir.join("tests").join(source)},
        "profile": {"test": true},
        "executable": dir.join(name),
    })
    .to_string()
}

/// `test_binaries.py`, the suite's runner, on fake test binaries (shell scripts) run two at a
/// time: each one's output printed whole under its name, in its package's directory, the
/// harness's arguments passed on; a binary that fails, or cannot start, makes the suite fail
/// by name; the two binaries whose lavapipe runs grow to gigabytes never overlap, though a
/// lane is free beside the first (each takes 1 s, and they are the longest, so they would start
/// together); a line that is not a cargo message is refused by its number, running nothing.
#[test]
fn the_test_runner_reports_each_binary_and_fails_when_one_fails() {
    use std::os::unix::fs::PermissionsExt;
    let dir = std::env::temp_dir().join(format!("flume-runner-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("dir");
    let spans = dir.join("spans");
    let span = |name: &str| {
        format!(
            "echo \"{name} $(date +%s.%N) start\" >> {0}; sleep 1; \
             echo \"{name} $(date +%s.%N) end\" >> {0}",
            spans.display()
        )
    };
    for (name, body) in [
        (
            "good",
            "echo \"in $(pwd) with $*\"; echo 'test result: ok. 2 passed;'".into(),
        ),
        (
            "bad",
            "echo 'test result: FAILED. 0 passed; 1 failed;'; exit 101".into(),
        ),
        ("weir", span("weir")),
        ("session", span("session")),
    ] {
        let path = dir.join(name);
        std::fs::write(&path, format!("#!/bin/sh\n{body}\n")).expect("script");
        std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o755)).expect("chmod");
    }
    let artifacts = dir.join("artifacts.json");
    let run = |lines: &[String]| {
        std::fs::write(&artifacts, lines.join("\n")).expect("artifacts");
        Command::new("python3")
            .arg(repo_file("scripts/test_binaries.py"))
            .arg(&artifacts)
            .args(["--", "--nocapture"])
            .env("TEST_LANES", "2")
            .output()
            .expect("python3 runs")
    };
    let out = run(&[
        test_artifact(&dir, "fake", "good", "good.rs"),
        test_artifact(&dir, "fake", "bad", "bad.rs"),
        test_artifact(&dir, "fake", "missing", "missing.rs"),
        test_artifact(&dir, "flume-solver", "weir", "weir.rs"),
        test_artifact(&dir, "flume-solver", "session", "whole_session.rs"),
    ]);
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    assert_eq!(out.status.code(), Some(1), "{text}");
    let good = format!(
        "Running fake tests/good.rs ({})\nin {} with --nocapture\n",
        dir.join("good").display(),
        dir.display()
    );
    assert!(text.contains(&good), "{text}");
    assert!(text.contains("fake tests/bad.rs: exit 101"), "{text}");
    assert!(
        text.contains("failed: fake tests/bad.rs, fake tests/missing.rs")
            || text.contains("failed: fake tests/missing.rs, fake tests/bad.rs"),
        "{text}"
    );
    let spans = std::fs::read_to_string(&spans).expect("the apart binaries ran");
    let times: Vec<(&str, f64)> = spans
        .lines()
        .map(|l| {
            let mut w = l.split(' ');
            let name = w.next().expect("name");
            (name, w.next().expect("time").parse().expect("seconds"))
        })
        .collect();
    let (first, second) = (&times[..2], &times[2..]);
    assert!(
        first[0].0 == first[1].0 && second[0].0 == second[1].0 && first[1].1 <= second[0].1,
        "the two ran at once: {spans}"
    );
    let out = run(&[
        test_artifact(&dir, "fake", "good", "good.rs"),
        "{not json".into(),
    ]);
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("artifacts.json:2"), "{err}");
    assert!(String::from_utf8_lossy(&out.stdout).is_empty());
    std::fs::remove_dir_all(&dir).ok();
}

/// `test_binaries.py` stopped by SIGTERM (as a CI timeout or Ctrl-C stops it): the binary that
/// runs is killed with what it started (a `sleep` it left behind would outlive it), no binary
/// starts after, and the runner says so with status 130.
#[test]
fn the_test_runner_stops_its_binaries_and_their_children_when_stopped() {
    use std::os::unix::fs::PermissionsExt;
    let dir = std::env::temp_dir().join(format!("flume-runner-stop-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("dir");
    let (pid_file, later) = (dir.join("grandchild"), dir.join("later-ran"));
    for (name, body) in [
        (
            "long",
            format!("sleep 60 & echo $! > {}; wait", pid_file.display()),
        ),
        ("later", format!("touch {}", later.display())),
    ] {
        let path = dir.join(name);
        std::fs::write(&path, format!("#!/bin/sh\n{body}\n")).expect("script");
        std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o755)).expect("chmod");
    }
    let artifacts = dir.join("artifacts.json");
    let lines = [
        test_artifact(&dir, "fake", "long", "long.rs"),
        test_artifact(&dir, "fake", "later", "later.rs"),
    ];
    std::fs::write(&artifacts, lines.join("\n")).expect("artifacts");
    let runner = Command::new("python3")
        .arg(repo_file("scripts/test_binaries.py"))
        .arg(&artifacts)
        .env("TEST_LANES", "1")
        .stdout(std::process::Stdio::piped())
        .spawn()
        .expect("python3 runs");
    let started = Instant::now();
    let grandchild = loop {
        let pid = std::fs::read_to_string(&pid_file).unwrap_or_default();
        if let Ok(pid) = pid.trim().parse::<u32>() {
            break pid;
        }
        assert!(
            started.elapsed() < Duration::from_secs(20),
            "the long binary never ran"
        );
        std::thread::sleep(Duration::from_millis(50));
    };
    let term = Command::new("kill")
        .args(["-TERM", &runner.id().to_string()])
        .status();
    assert!(term.expect("kill runs").success());
    let out = runner.wait_with_output().expect("the runner ends");
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    assert_eq!(out.status.code(), Some(130), "{text}");
    assert!(text.contains("interrupted"), "{text}");
    // A killed process may stand a moment as a zombie before its new parent reaps it.
    let alive = |pid: u32| {
        std::fs::read_to_string(format!("/proc/{pid}/stat")).is_ok_and(|s| {
            s.rsplit(')')
                .next()
                .is_some_and(|r| !r.trim().starts_with('Z'))
        })
    };
    let gone = (0..100).any(|_| {
        std::thread::sleep(Duration::from_millis(50));
        !alive(grandchild)
    });
    assert!(
        gone,
        "the long binary's sleep {grandchild} outlived the runner"
    );
    assert!(
        !later.exists(),
        "a binary started after the runner was stopped"
    );
    std::fs::remove_dir_all(&dir).ok();
}
