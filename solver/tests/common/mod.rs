//! Shared test helpers: the GPU (lavapipe in CI), serialised, and small case builders.

#![allow(dead_code)]

use flume_solver::GpuContext;
use std::sync::{Arc, Mutex, MutexGuard, OnceLock};

/// GPU tests run one at a time: lavapipe already uses every core.
pub fn gpu_lock() -> MutexGuard<'static, ()> {
    static LOCK: Mutex<()> = Mutex::new(());
    LOCK.lock().unwrap_or_else(|e| e.into_inner())
}

/// The adapter, or None outside CI when this machine has none (then the test says so and
/// passes); under CI=true a missing adapter fails the test, since CI has lavapipe.
pub fn gpu() -> Option<Arc<GpuContext>> {
    static GPU: OnceLock<Option<Arc<GpuContext>>> = OnceLock::new();
    GPU.get_or_init(|| match GpuContext::new() {
        Ok(g) => {
            eprintln!("adapter: {}", g.adapter);
            Some(Arc::new(g))
        }
        Err(e) => {
            if std::env::var("CI").as_deref() == Ok("true") {
                panic!("CI=true but no GPU adapter: {e}");
            }
            eprintln!("skipping GPU test: {e}");
            None
        }
    })
    .clone()
}

pub fn case_path(name: &str) -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(name)
}

pub fn validation_path(name: &str) -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../shared/validation")
        .join(name)
}
