//! What the binary's tests share: repository paths and the GPU gate.
//!
//! GPU tests skip with a note when no adapter is found, except under CI=true (CI has lavapipe),
//! where a missing adapter is a failure. Within a test binary they run one at a time: lavapipe
//! uses every core.

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
