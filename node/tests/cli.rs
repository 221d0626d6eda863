//! The flume-twin binary as a user runs it: bad case files, a short simulate run and its
//! output files, and the missing-adapter message.

mod common;

use common::vtk::{check_vtk_header, read_with_meshio};
use common::{csv_rows, gpu, repo_file};
use std::fs;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const BIN: &str = env!("CARGO_BIN_EXE_flume-twin");

/// A fresh, empty directory for one test's files.
fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("cli")
        .join(name);
    let _ = fs::remove_dir_all(&dir);
    fs::create_dir_all(&dir).unwrap();
    dir
}

fn flume_twin(args: &[&str]) -> Output {
    Command::new(BIN).args(args).output().unwrap()
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// The verification case with one textual change, written to `dir`.
fn edited_case(dir: &Path, from: &str, to: &str) -> PathBuf {
    let original = fs::read_to_string(repo_file("launch_configs/dambreak_water.yaml")).unwrap();
    assert!(
        original.contains(from),
        "the case file no longer contains {from:?}"
    );
    let path = dir.join("case.yaml");
    fs::write(&path, original.replacen(from, to, 1)).unwrap();
    path
}

/// Runs `simulate` on the dam-break case with one edit and returns its stderr, asserting that
/// it failed and wrote no outputs.
fn refused_edit(name: &str, from: &str, to: &str) -> String {
    let dir = scratch(name);
    let case = edited_case(&dir, from, to);
    let out = flume_twin(&[
        "simulate",
        case.to_str().unwrap(),
        "--out",
        dir.join("out").to_str().unwrap(),
    ]);
    let stderr = text(&out.stderr);
    assert!(!out.status.success(), "accepted {to:?}; stderr: {stderr}");
    assert!(
        !dir.join("out").exists(),
        "a refused case must not create outputs"
    );
    stderr
}

#[test]
fn unknown_field_is_refused_by_name() {
    let stderr = refused_edit(
        "unknown_field",
        "  coefh: 1.2\n",
        "  coefh: 1.2\n  bogus_knob: 3\n",
    );
    assert!(
        stderr.contains("numerics.bogus_knob"),
        "stderr does not name the field: {stderr}"
    );
}

#[test]
fn negative_dp_is_refused_by_name() {
    let stderr = refused_edit("negative_dp", "dp_m: 0.0025", "dp_m: -0.0025");
    assert!(
        stderr.contains("numerics.dp_m"),
        "stderr does not name the field: {stderr}"
    );
}

/// `bench --levels` refuses what it cannot run before any run starts, saying which flag: a
/// resolution that is no length, a run too short for a drift, a value the case refuses, an
/// empty collector pit asked of the fixed bed, whose pit is part of its clear-water block.
#[test]
fn bench_levels_refuses_bad_flags_before_it_runs() {
    let cases: [(&[&str], &str); 4] = [
        (&["--fixed-bed", "--empty-pit"], "--empty-pit"),
        (
            &["--dp", "0.01,-0.007"],
            "--dp: -0.007 is not a positive length",
        ),
        (&["--until", "5"], "--until: 5 s is too short"),
        (
            &["--dp", "0.01", "--set", "numerics.cfl=-1"],
            "numerics.cfl",
        ),
    ];
    for (args, want) in cases {
        let flume = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../launch_configs/ulbra_flume.yaml"
        );
        let mut all = vec!["bench", "--levels", "--flume", flume];
        all.extend(args);
        assert_refused_first(&all, want, "backend:");
    }
}

/// `flume-twin ARGS` fails, its error names `want`, and it printed no `work` line first.
fn assert_refused_first(all: &[&str], want: &str, work: &str) {
    let out = flume_twin(all);
    let stderr = text(&out.stderr);
    assert!(!out.status.success(), "{all:?} ran");
    assert!(stderr.contains(want), "{all:?}: {stderr}");
    assert!(
        !text(&out.stdout).contains(work),
        "{all:?} started before refusing"
    );
}

/// The timing `bench` refuses a start time that is no flume time and a value the flume case
/// refuses, saying which, before any measurement starts.
#[test]
fn bench_refuses_bad_flags_before_it_times() {
    let cases: [(&[&str], &str); 2] = [
        (&["--from", "-1"], "--from: -1 s"),
        (&["--set", "numerics.cfl=-1"], "numerics.cfl"),
    ];
    for (args, want) in cases {
        let (case, flume) = (
            repo_file("launch_configs/dsph_dambreak_val2d.yaml"),
            repo_file("launch_configs/ulbra_flume.yaml"),
        );
        let mut all = vec!["bench", "--ladder", "4000", "--steps-seconds", "0.1"];
        all.extend([
            "--case",
            case.to_str().unwrap(),
            "--flume",
            flume.to_str().unwrap(),
        ]);
        all.extend(args);
        assert_refused_first(&all, want, "particle-steps");
    }
}

#[test]
fn missing_case_file_is_reported() {
    let dir = scratch("missing_case");
    let missing = dir.join("no_such_case.yaml");
    let out = flume_twin(&["simulate", missing.to_str().unwrap()]);
    assert!(!out.status.success());
    assert!(
        text(&out.stderr).contains("no_such_case.yaml"),
        "{}",
        text(&out.stderr)
    );
}

/// `simulate` with the Vulkan loader pointed at no driver, and `FLUME_TWIN_ADAPTER` set to
/// `adapter` (None: unset).
fn simulate_without_a_driver(dir: &std::path::Path, adapter: Option<&str>) -> std::process::Output {
    // WGPU_BACKEND=vulkan keeps wgpu off GL (llvmpipe would answer there); the two loader
    // variables (new and legacy name) point the Vulkan loader at no driver at all.
    let mut cmd = Command::new(BIN);
    cmd.args([
        "simulate",
        repo_file("launch_configs/dambreak_water.yaml")
            .to_str()
            .unwrap(),
    ])
    .args([
        "--until",
        "0.001",
        "--out",
        dir.join("out").to_str().unwrap(),
    ])
    .env("WGPU_BACKEND", "vulkan")
    .env("VK_ICD_FILENAMES", "/nonexistent.json")
    .env("VK_DRIVER_FILES", "/nonexistent.json")
    .env_remove("FLUME_TWIN_ADAPTER");
    if let Some(a) = adapter {
        cmd.env("FLUME_TWIN_ADAPTER", a);
    }
    cmd.output().unwrap()
}

/// Without any adapter the twin runs on the CPU backend and says so; asked for an adapter
/// that is not there, it fails and says how to get lavapipe.
#[test]
fn without_an_adapter_the_cpu_backend_runs_and_a_named_one_says_how_to_get_it() {
    let dir = scratch("no_adapter");
    let out = simulate_without_a_driver(&dir, None);
    let stdout = text(&out.stdout);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(
        stdout.starts_with("adapter: native CPU backend"),
        "{stdout}"
    );
    let out = simulate_without_a_driver(&dir, Some("llvmpipe"));
    let stderr = text(&out.stderr);
    assert!(
        !out.status.success(),
        "found an adapter with no driver; stdout: {}",
        text(&out.stdout)
    );
    assert!(
        stderr.contains("mesa-vulkan-drivers"),
        "no install hint: {stderr}"
    );
}

#[test]
fn short_run_writes_gauges_and_snapshots() {
    let Some(_gpu) = gpu() else { return };
    let dir = scratch("short_run");
    let out_dir = dir.join("out");
    let out = flume_twin(&[
        "simulate",
        repo_file("launch_configs/dambreak_water.yaml")
            .to_str()
            .unwrap(),
        "--until",
        "0.01",
        "--out",
        out_dir.to_str().unwrap(),
    ]);
    let stdout = text(&out.stdout);
    assert!(
        out.status.success(),
        "simulate failed: {}\n{stdout}",
        text(&out.stderr)
    );
    assert!(stdout.starts_with("adapter: "), "{stdout}");
    assert!(stdout.contains("real-time factor"), "no summary: {stdout}");

    let csv = fs::read_to_string(out_dir.join("gauges.csv")).unwrap();
    let mut lines = csv.lines();
    let header = lines.next().unwrap();
    assert_eq!(
        header,
        "time_s,step,dt_s,front_m,max_speed_m_per_s,max_density_error,cfl,recoveries,near_wall_m,mid_tank_m,toe_pa"
    );
    let rows: Vec<&str> = lines.collect();
    assert!(rows.len() >= 2, "{csv}");
    for row in &rows {
        assert_eq!(row.split(',').count(), 11, "row {row:?}");
    }
    let last_time: f64 = rows
        .last()
        .unwrap()
        .split(',')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    assert!(
        (last_time - 0.01).abs() < 1e-12,
        "last row at t = {last_time}"
    );

    // The case's 13 profile columns, per output row, with the surface of the column at the
    // dam (x = 0.05 m, inside the column 0.2 m high) near its height.
    let profile = fs::read_to_string(out_dir.join("profile.csv")).unwrap();
    let mut lines = profile.lines();
    assert_eq!(lines.next().unwrap(), "time_s,x_m,surface_m,water_top_m");
    let profile_rows: Vec<&str> = lines.collect();
    assert_eq!(profile_rows.len(), 13 * rows.len(), "{profile}");
    let at_dam: f64 = profile_rows[1].split(',').nth(2).unwrap().parse().unwrap();
    assert!(
        (at_dam - 0.2).abs() < 0.01,
        "surface at x = 0.05 m: {at_dam}"
    );

    let particles: usize = stdout
        .lines()
        .find_map(|l| l.strip_prefix("particles: "))
        .and_then(|l| l.split_whitespace().next())
        .and_then(|n| n.parse().ok())
        .expect("a `particles: N` line");
    let mut snapshots: Vec<PathBuf> = fs::read_dir(&out_dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "vtk"))
        .collect();
    snapshots.sort();
    assert!(!snapshots.is_empty(), "no .vtk in {}", out_dir.display());
    check_vtk_header(&fs::read(snapshots.last().unwrap()).unwrap(), particles);
    read_with_meshio(snapshots.last().unwrap(), particles);
}

#[test]
fn blow_up_exits_non_zero_and_keeps_outputs() {
    let Some(_gpu) = gpu() else { return };
    let dir = scratch("blow_up");
    // c0 = 5 m/s is far below 10 times the flow speed (about 1.4 m/s): densities run away
    // within a few hundredths of a second, whatever the time step.
    let case = edited_case(
        &dir,
        "sound_speed: { coefsound: 20.0 }",
        "sound_speed: { c0_m_per_s: 5.0 }",
    );
    let out_dir = dir.join("out");
    let out = flume_twin(&[
        "simulate",
        case.to_str().unwrap(),
        "--until",
        "0.3",
        "--out",
        out_dir.to_str().unwrap(),
    ]);
    let stderr = text(&out.stderr);
    assert!(
        !out.status.success(),
        "a c0 of 5 m/s ran to the end: {}",
        text(&out.stdout)
    );
    assert!(stderr.contains("blew up"), "{stderr}");
    let csv = fs::read_to_string(out_dir.join("gauges.csv")).unwrap();
    assert!(
        csv.lines().count() >= 3,
        "rows before the failure were lost: {csv}"
    );
    assert!(out_dir.join("particles_0001.vtk").exists());
    // The error names the particles furthest from health, and the failed state marks them.
    assert!(stderr.contains("worst particles: id "), "{stderr}");
    let failed = fs::read(out_dir.join("particles_failed.vtk")).unwrap();
    assert!(
        failed.windows(21).any(|w| w == b"SCALARS culprit int 1"),
        "particles_failed.vtk marks no culprit"
    );
}

/// A case whose own inflow the inlet cannot carry (5 m3/s through a 2 cm x 8.6 cm opening,
/// 2,900 m/s) is refused before it runs, naming the field and the limit, 0.3 c0 through the
/// opening with c0 = 10 m/s: 5.16e-3 m3/s. It used to blow up at t = 4 us after four retries.
#[test]
fn an_inflow_the_inlet_cannot_carry_is_refused_up_front() {
    let dir = scratch("inflow_too_big");
    let out_dir = dir.join("out");
    let out = flume_twin(&[
        "simulate",
        repo_file("launch_configs/ulbra_flume.yaml")
            .to_str()
            .unwrap(),
        "--set",
        "numerics.dp_m=0.01",
        "--set",
        "open_flume.inflow_m3_per_s=5",
        "--until",
        "0.01",
        "--out",
        out_dir.to_str().unwrap(),
    ]);
    let stderr = text(&out.stderr);
    assert!(!out.status.success(), "it ran: {}", text(&out.stdout));
    assert!(stderr.contains("open_flume.inflow_m3_per_s"), "{stderr}");
    assert!(stderr.contains("at most 5.1600e-3 m3/s"), "{stderr}");
    assert!(!out_dir.exists(), "outputs were started for a refused case");
}

/// `--inflow` is checked before the GPU is opened: a case without an open flume, and a series
/// with a negative discharge, each fail with the reason (and the line).
#[test]
fn a_bad_inflow_series_is_refused_with_its_line() {
    let dir = scratch("inflow");
    let series = dir.join("q.csv");
    fs::write(&series, "t_s,q_m3_per_s\n0,0.0005\n5,-0.001\n").unwrap();
    let series = series.to_str().unwrap();
    for (case, reason) in [
        ("launch_configs/dambreak_water.yaml", "has no open_flume"),
        (
            "launch_configs/ulbra_flume.yaml",
            "line 3: discharge -0.001 m3/s must be finite and >= 0",
        ),
    ] {
        let case = repo_file(case);
        let out = flume_twin(&["simulate", case.to_str().unwrap(), "--inflow", series]);
        assert!(!out.status.success());
        let err = text(&out.stderr);
        assert!(err.contains(reason), "{err}");
    }
}

/// A flume run writes the scour outputs: bed_profile.csv, eroded_mass.csv (whose discharge is
/// the --inflow series' at each row's time) and bed.png.
#[test]
fn a_flume_run_writes_bed_profile_eroded_mass_and_the_bed_plot() {
    let Some(_gpu) = gpu() else { return };
    let dir = scratch("flume_run");
    let out_dir = dir.join("out");
    let series = dir.join("q.csv");
    fs::write(&series, "t_s,q_m3_per_s\n0,0.0005\n0.02,0.0006\n").unwrap();
    let out = flume_twin(&[
        "simulate",
        repo_file("solver/tests/cases/recycle_2d.yaml")
            .to_str()
            .unwrap(),
        "--until",
        "0.05",
        "--no-snapshots",
        "--inflow",
        series.to_str().unwrap(),
        "--out",
        out_dir.to_str().unwrap(),
    ]);
    let stdout = text(&out.stdout);
    assert!(
        out.status.success(),
        "simulate failed: {}\n{stdout}",
        text(&out.stderr)
    );
    let eroded = fs::read_to_string(out_dir.join("eroded_mass.csv")).unwrap();
    let rows: Vec<Vec<&str>> = eroded
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect())
        .collect();
    assert_eq!(rows.len(), 2, "{eroded}");
    assert_eq!((rows[0][0], rows[0][1]), ("0", "0.0005"), "{eroded}");
    assert_eq!((rows[1][0], rows[1][1]), ("0.05", "0.0006"), "{eroded}");
    let bed = fs::read_to_string(out_dir.join("bed_profile.csv")).unwrap();
    assert!(bed.starts_with("time_s,x_m,zb_m,zs_m,zw_m\n"), "{bed}");
    let png = fs::read(out_dir.join("bed.png")).unwrap();
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    assert!(stdout.contains("bed plot: "), "{stdout}");
}

/// The launch file is well-formed XML that starts `flume-twin run` with the shipped parameter
/// file, and the rviz config is YAML that shows the twin's particle and bed-line topics.
#[test]
fn the_launch_file_and_rviz_config_are_well_formed() {
    let launch = repo_file("launch_configs/flume_twin.launch.xml");
    let out = std::process::Command::new("python3")
        .args([
            "-c",
            "import sys, xml.etree.ElementTree as E; r = E.parse(sys.argv[1]).getroot(); \
             print(r.tag, r.find('executable').get('cmd'))",
            launch.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    let printed = text(&out.stdout);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(printed.starts_with("launch flume-twin run "), "{printed}");
    assert!(printed.contains("--params-file $(var params)"), "{printed}");
    let rviz = fs::read_to_string(repo_file("launch_configs/flume_twin.rviz")).unwrap();
    assert!(rviz.contains("Value: /flume/particles") && rviz.contains("Value: /flume/bed_marker"));
    let yaml: serde_norway::Value = serde_norway::from_str(&rviz).unwrap();
    assert_eq!(
        yaml["Visualization Manager"]["Global Options"]["Fixed Frame"],
        serde_norway::Value::from("flume")
    );
}

/// A normal start prints the twin's own lines and nothing to alarm a user: no ERROR (RustDDS
/// once reported a /clock type clash with ros2-client's spinner at each start), no warning
/// that asks nothing of them (`ROS_DISTRO` unset, iceoryx2 on its defaults), and nothing from
/// Mesa when `XDG_RUNTIME_DIR` is unset, as under a service manager. Both streams are read in
/// order, up to the twin reaching --until; what RustDDS says at exit on loopback is apart.
#[test]
fn a_normal_start_prints_nothing_alarming() {
    let out = Command::new("sh")
        .args([
            "-c",
            "exec \"$0\" \"$@\" 2>&1",
            env!("CARGO_BIN_EXE_flume-twin"),
        ])
        .arg("run")
        .arg(repo_file("solver/tests/cases/recycle_2d.yaml"))
        .args(["--loopback", "--no-replay", "--until", "0.3"])
        .args(["--ros-args", "-r", "__ns:=/flume_quiet"])
        .env_remove("XDG_RUNTIME_DIR")
        .env_remove("RUST_LOG")
        .env_remove("ROS_DISTRO")
        .output()
        .expect("runs the twin");
    let said = text(&out.stdout);
    assert!(out.status.success(), "{said}");
    assert!(said.contains("reached t = 0.300 s"), "{said}");
    let start = said
        .split("reached t = ")
        .next()
        .expect("the output up to --until");
    for expected in [
        "adapter: ",
        "particles: ",
        "node: /flume_quiet flume_twin",
        "listening: ",
    ] {
        assert!(start.contains(expected), "no {expected:?} in:\n{said}");
    }
    for line in start.lines() {
        let alarming = ["ERROR", "WARN", "error", "[W]", "XDG_RUNTIME_DIR"]
            .iter()
            .any(|a| line.contains(a));
        assert!(!alarming, "{line:?} at start:\n{said}");
    }
}

/// A flume whose bed is a wall block (the clear-water flume of `bench --levels --fixed-bed`)
/// has a profile but no sediment in it: the run ends normally and says there is no bed plot
/// (it used to end with an error after the whole run).
#[test]
fn a_clear_water_flume_run_ends_without_a_bed_plot() {
    let dir = scratch("clear_water_run");
    let path = repo_file("launch_configs/ulbra_flume.yaml");
    let sand = flume_solver::Case::from_path_with(&path, &["numerics.dp_m=0.01".to_string()])
        .expect("the flume case");
    let overrides = flume_solver::hydraulics::fixed_bed_overrides(&sand).expect("a bed");
    let mut args = vec![
        "simulate".to_string(),
        path.to_str().unwrap().to_string(),
        "--set".into(),
        "numerics.dp_m=0.01".into(),
        "--until".into(),
        "0.05".into(),
        "--no-snapshots".into(),
        "--out".into(),
        dir.join("out").to_str().unwrap().to_string(),
    ];
    for o in overrides {
        args.extend(["--set".to_string(), o]);
    }
    let out = flume_twin(&args.iter().map(String::as_str).collect::<Vec<_>>());
    let stdout = text(&out.stdout);
    assert!(
        out.status.success(),
        "simulate failed: {}\n{stdout}",
        text(&out.stderr)
    );
    assert!(stdout.contains("bed plot: none"), "{stdout}");
    assert!(!dir.join("out/bed.png").exists());
}

/// The sediment budget of a flume run: the short flume whose cloud of sand sinks into the
/// collector. At every output its books close (the grains in each place add up to those
/// mobilised), and the grains it finds no longer sand, followed by id, are the ones the flume's
/// own counters took out of the sand (eroded_mass.csv's, counted where the store pass collects
/// them, plus those excluded for their density); some are, by 0.3 s.
#[test]
fn a_flume_run_writes_a_sediment_budget_whose_books_close() {
    let dir = scratch("budget");
    let out_dir = dir.join("out");
    let out = flume_twin(&[
        "simulate",
        repo_file("solver/tests/cases/collector_2d.yaml")
            .to_str()
            .unwrap(),
        "--until",
        "0.3",
        "--no-snapshots",
        "--out",
        out_dir.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "simulate failed: {}",
        text(&out.stderr)
    );
    let budget = csv_rows(&out_dir.join("sediment_budget.csv"));
    let eroded = csv_rows(&out_dir.join("eroded_mass.csv"));
    assert_eq!(budget.len(), eroded.len(), "a budget row per output");
    let n = |r: &std::collections::BTreeMap<String, String>, k: &str| -> u64 {
        r[k].parse()
            .unwrap_or_else(|e| panic!("{k} = {:?}: {e}", r[k]))
    };
    for (b, e) in budget.iter().zip(&eroded) {
        assert_eq!(b["time_s"], e["time_s"]);
        let places: u64 = ["moving", "suspended", "deposited", "past_bed", "collected"]
            .iter()
            .map(|k| n(b, k))
            .sum();
        assert_eq!(places, n(b, "mobilised"), "{b:?}");
        let stretches: u64 = b
            .keys()
            .filter(|k| k.starts_with("mobilised_from_"))
            .map(|k| n(b, k))
            .sum();
        assert_eq!(stretches, n(b, "mobilised"), "{b:?}");
        assert_eq!(
            n(b, "collected"),
            n(e, "eroded_particles") + n(b, "excluded"),
            "at t = {} s",
            b["time_s"]
        );
    }
    let last = budget.last().expect("rows");
    assert!(n(last, "collected") > 0, "no sand collected: {last:?}");
    let png = fs::read(out_dir.join("sediment_budget.png")).unwrap();
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
}
