//! Which backend runs a case: a real GPU through wgpu when one is present, else the native CPU
//! backend; `FLUME_TWIN_ADAPTER` forces either (`cpu`, or any part of an adapter's name, such
//! as `llvmpipe` for lavapipe).

use crate::gpu::context::ADAPTER_ENV;
use crate::gpu::{GpuContext, GpuError};
use std::sync::Arc;

/// The value of `FLUME_TWIN_ADAPTER` that picks the CPU backend.
pub const CPU_BACKEND: &str = "cpu";

#[derive(Clone)]
pub enum Backend {
    /// The wgpu backend on this adapter.
    Gpu(Arc<GpuContext>),
    /// The native CPU backend on this many threads (0: one per core); with `awake_set`,
    /// walls and held grains far from moving fluid or deep under it skip their neighbour loops,
    /// which gives the same bits (`cpu/forces.rs`, `cpu/multiphase.rs`): false is the full
    /// computation it is checked against.
    Cpu { threads: usize, awake_set: bool },
}

impl From<Arc<GpuContext>> for Backend {
    fn from(gpu: Arc<GpuContext>) -> Backend {
        Backend::Gpu(gpu)
    }
}

impl From<&Arc<GpuContext>> for Backend {
    fn from(gpu: &Arc<GpuContext>) -> Backend {
        Backend::Gpu(Arc::clone(gpu))
    }
}

impl std::fmt::Debug for Backend {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.describe())
    }
}

impl Backend {
    /// The CPU backend on `threads` threads (0: one per core), with its awake set.
    pub const fn cpu(threads: usize) -> Backend {
        Backend::Cpu {
            threads,
            awake_set: true,
        }
    }

    /// The backend `FLUME_TWIN_ADAPTER` names, else a real (not software) GPU, else the CPU
    /// backend (faster than a software adapter on the same cores).
    pub fn choose() -> Result<Backend, GpuError> {
        let wanted = std::env::var(ADAPTER_ENV).ok().filter(|s| !s.is_empty());
        match wanted.as_deref() {
            Some(w) if w.eq_ignore_ascii_case(CPU_BACKEND) => Ok(Backend::cpu(0)),
            Some(w) => Ok(Backend::Gpu(Arc::new(GpuContext::with_adapter(Some(w))?))),
            None => Ok(Self::best()),
        }
    }

    fn best() -> Backend {
        match GpuContext::with_adapter(None) {
            Ok(g) if !g.is_software() => Backend::Gpu(Arc::new(g)),
            _ => Backend::cpu(0),
        }
    }

    /// A line naming the backend and its device.
    pub fn describe(&self) -> String {
        match self {
            Backend::Gpu(g) => format!("wgpu on {}", g.adapter),
            Backend::Cpu { threads, awake_set } => crate::cpu::describe(*threads, *awake_set),
        }
    }
}
