//! What the binary's tests share: repository paths, the GPU gate, the Python gate and the CSV
//! reader.
//!
//! GPU tests skip with a note when no adapter is found, except under CI=true (CI has lavapipe),
//! where a missing adapter is a failure. Within a test binary they run one at a time: lavapipe
//! uses every core.

// Each test binary compiles this module and uses part of it.
#![allow(dead_code)]

pub mod vtk;

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

/// Whether python3 can `import modules` (comma-separated); see [`ready`].
pub fn python_has(modules: &str, pip: &str) -> bool {
    let probe = std::process::Command::new("python3")
        .args(["-c", &format!("import {modules}")])
        .output();
    ready(
        probe.is_ok_and(|o| o.status.success()),
        &format!("python3 cannot import {modules}"),
        &format!("pip install {pip}"),
    )
}

/// `ok`, whether a reader a test needs is installed; without it the test skips with a note
/// saying how to install it (`install`), except under CI=true, where `scripts/test.sh`
/// installs it and a miss (`missing`) is a failure.
pub fn ready(ok: bool, missing: &str, install: &str) -> bool {
    if !ok {
        assert!(
            std::env::var("CI").as_deref() != Ok("true"),
            "CI=true and {missing} (scripts/test.sh installs it)"
        );
        eprintln!("note: skipping, {install}");
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

/// The ULBRA flume at CI size (dp = 1 cm, 4,582 particles) as the twin runs it
/// (`scripts/run.sh`): the arguments after the case file. At this dp the flow is two to four
/// particles deep, and the paper's choices (DBC walls, alpha = 0.02, the release at once) hold
/// the water 2-3 cm too high and rising; the twin takes the generalised walls, the flow's eddy
/// viscosity at 2 m3/h, van Rijn's pick-up worn off the bed net of what settles on it (Exner's
/// balance), the Shields test on the water's own speed, and grains held again only beside a
/// solid (README, levels and sediment sections).
pub const ULBRA_CI: [&str; 14] = [
    "--set",
    "numerics.dp_m=0.01",
    "--set",
    "open_flume.reservoir_particles=2500",
    "--set",
    "numerics.boundary={method: generalised}",
    "--set",
    "numerics.viscosity={method: multiphase, eddy_m2_per_s: 3.95e-5}",
    "--set",
    "phases.1.sediment.erosion=van_rijn_exner",
    "--set",
    "phases.1.sediment.shields_speed=water",
    "--set",
    "phases.1.sediment.comes_to_rest=beside_a_solid",
];

/// `flume-twin run` on the CI-size ULBRA flume from the repository's root (where the bundled
/// session is, as for the README's command), DDS on loopback only; the test adds its own
/// options.
pub fn ulbra_twin() -> std::process::Command {
    let mut twin = std::process::Command::new(env!("CARGO_BIN_EXE_flume-twin"));
    twin.current_dir(repo_file(""))
        .args(["run", "launch_configs/ulbra_flume.yaml"])
        .args(ULBRA_CI)
        .arg("--loopback");
    twin
}

/// `flume-twin run` on the small recycling tank (`recycle_2d.yaml`), DDS on loopback only and
/// no recorded session in the sensors' place; the test adds its own options.
pub fn recycle_twin() -> std::process::Command {
    let mut twin = std::process::Command::new(env!("CARGO_BIN_EXE_flume-twin"));
    twin.arg("run")
        .arg(repo_file("solver/tests/cases/recycle_2d.yaml"))
        .args(["--loopback", "--no-replay"]);
    twin
}

/// A child process killed however the test ends.
pub struct KillOnDrop(pub std::process::Child);

impl Drop for KillOnDrop {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// A recording as Python's `mcap` and `mcap-ros2-support` read it
/// (`tests/interop/read_mcap.py`), with the messages of `topics` decoded.
pub fn read_mcap<S: AsRef<std::ffi::OsStr>>(path: &Path, topics: &[S]) -> serde_json::Value {
    interop_json("read_mcap.py", path, topics)
}

/// What an independent reader (`tests/interop/SCRIPT PATH ARGS...`) printed as JSON.
pub fn interop_json<S: AsRef<std::ffi::OsStr>>(
    script: &str,
    path: &Path,
    args: &[S],
) -> serde_json::Value {
    let out = std::process::Command::new("python3")
        .arg(repo_file(&format!("tests/interop/{script}")))
        .arg(path)
        .args(args)
        .output()
        .expect("runs python3");
    assert!(
        out.status.success(),
        "{script} failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("JSON")
}

/// A child process whose output (stdout and stderr, a line at a time) is read as it comes, so
/// that a full pipe never blocks it, and which is killed when the test ends before it does.
pub struct Proc {
    child: std::process::Child,
    lines: std::sync::mpsc::Receiver<String>,
    said: std::sync::Arc<Mutex<Vec<String>>>,
}

impl Proc {
    pub fn spawn(what: &mut std::process::Command) -> Proc {
        use std::io::{BufRead, BufReader, Read};
        let mut child = what
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap_or_else(|e| panic!("{what:?} does not start: {e}"));
        let (tx, lines) = std::sync::mpsc::channel();
        let said = std::sync::Arc::new(Mutex::new(Vec::new()));
        let streams: [Box<dyn Read + Send>; 2] = [
            Box::new(child.stdout.take().expect("stdout")),
            Box::new(child.stderr.take().expect("stderr")),
        ];
        for stream in streams {
            let (tx, said) = (tx.clone(), std::sync::Arc::clone(&said));
            std::thread::spawn(move || {
                for line in BufReader::new(stream).lines().map_while(Result::ok) {
                    said.lock()
                        .unwrap_or_else(|p| p.into_inner())
                        .push(line.clone());
                    let _ = tx.send(line);
                }
            });
        }
        Proc { child, lines, said }
    }

    pub fn pid(&self) -> u32 {
        self.child.id()
    }

    /// Everything it has printed so far.
    pub fn said(&self) -> String {
        self.said
            .lock()
            .unwrap_or_else(|p| p.into_inner())
            .join("\n")
    }

    /// Waits at most `limit` for a line that starts with `prefix`.
    pub fn wait_for(&self, prefix: &str, limit: std::time::Duration) {
        let deadline = std::time::Instant::now() + limit;
        loop {
            let left = deadline.saturating_duration_since(std::time::Instant::now());
            match self.lines.recv_timeout(left) {
                Ok(line) if line.starts_with(prefix) => return,
                Ok(_) => continue,
                Err(_) => panic!(
                    "no line starting {prefix:?} within {limit:?}:\n{}",
                    self.said()
                ),
            }
        }
    }

    /// Waits at most `limit` for it to end (killing it past that, and failing); whether it
    /// succeeded, and everything it printed.
    pub fn finish(&mut self, limit: std::time::Duration) -> (bool, String) {
        let deadline = std::time::Instant::now() + limit;
        let status = loop {
            if let Some(status) = self.child.try_wait().expect("wait") {
                break status;
            }
            if std::time::Instant::now() > deadline {
                let _ = self.child.kill();
                panic!("still running after {limit:?}:\n{}", self.said());
            }
            std::thread::sleep(std::time::Duration::from_millis(100));
        };
        // The readers end at the pipes' end.
        while self
            .lines
            .recv_timeout(std::time::Duration::from_secs(5))
            .is_ok()
        {}
        (status.success(), self.said())
    }
}

impl Drop for Proc {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// Reads a child's output up to the first line that starts with `prefix` and returns it, with
/// a thread that drains the rest (a full pipe would stall the child) and gives it back at the
/// end. Panics if the output ends first.
pub fn read_until(
    out: std::process::ChildStdout,
    prefix: &str,
) -> (String, std::thread::JoinHandle<String>) {
    use std::io::{BufRead, Read};
    let mut out = std::io::BufReader::new(out);
    let mut seen = String::new();
    loop {
        let start = seen.len();
        let read = out.read_line(&mut seen).expect("the child's output");
        assert!(read > 0, "the output ended before {prefix:?}:\n{seen}");
        if seen[start..].starts_with(prefix) {
            break;
        }
    }
    let rest = std::thread::spawn(move || {
        let mut rest = String::new();
        let _ = out.read_to_string(&mut rest);
        rest
    });
    (seen, rest)
}
