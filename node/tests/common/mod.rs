//! What the binary's tests share: repository paths, the GPU gate, the Python gate and the CSV
//! reader.
//!
//! GPU tests skip with a note when no adapter is found, except under CI=true (CI has lavapipe),
//! where a missing adapter is a failure. Within a test binary they run one at a time: lavapipe
//! uses every core.

// Each test binary compiles this module and uses part of it.
#![allow(dead_code)]

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard};

static GPU: Mutex<()> = Mutex::new(());

pub fn repo_file(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..").join(rel)
}

/// Holds the GPU lock if an adapter is there; None (after a note) if the test should skip.
pub fn gpu() -> Option<MutexGuard<'static, ()>> {
    let guard = GPU.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
    match flume_solver::GpuContext::new() {
        Ok(_) => Some(guard),
        Err(e) if std::env::var("CI").as_deref() == Ok("true") => {
            panic!("CI=true and no GPU adapter: {e}")
        }
        Err(e) => {
            eprintln!("note: skipping a GPU test, no adapter: {e}");
            None
        }
    }
}

/// Rows of a CSV file as maps from column to value.
pub fn csv_rows(path: &Path) -> Vec<BTreeMap<String, String>> {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut lines = text.lines();
    let header: Vec<String> = lines
        .next()
        .expect("a header")
        .split(',')
        .map(str::to_string)
        .collect();
    lines
        .map(|l| {
            header
                .iter()
                .cloned()
                .zip(l.split(',').map(str::to_string))
                .collect()
        })
        .collect()
}

/// Whether python3 can `import modules` (comma-separated); without them a test skips with a
/// note, except under CI=true, where `scripts/test.sh` installs them and a miss is a failure.
pub fn python_has(modules: &str, pip: &str) -> bool {
    let ok = std::process::Command::new("python3")
        .args(["-c", &format!("import {modules}")])
        .output()
        .is_ok_and(|o| o.status.success());
    if !ok {
        assert!(
            std::env::var("CI").as_deref() != Ok("true"),
            "CI=true and python3 cannot import {modules} (scripts/test.sh installs them)"
        );
        eprintln!("note: skipping, pip install {pip}");
    }
    ok
}

/// What a finished process printed, stdout then stderr.
pub fn printed(out: &std::process::Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    )
}

/// The ULBRA flume at CI size (dp = 1 cm, 4,570 particles), as solver/tests/scour.rs builds
/// it: the arguments after the case file.
pub const ULBRA_CI: [&str; 4] = [
    "--set",
    "numerics.dp_m=0.01",
    "--set",
    "open_flume.reservoir_particles=2500",
];

/// A recording as Python's `mcap` and `mcap-ros2-support` read it
/// (`tests/interop/read_mcap.py`), with the messages of `topics` decoded.
pub fn read_mcap<S: AsRef<std::ffi::OsStr>>(path: &Path, topics: &[S]) -> serde_json::Value {
    let out = std::process::Command::new("python3")
        .arg(repo_file("tests/interop/read_mcap.py"))
        .arg(path)
        .args(topics)
        .output()
        .expect("runs python3");
    assert!(
        out.status.success(),
        "read_mcap.py failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("JSON")
}
