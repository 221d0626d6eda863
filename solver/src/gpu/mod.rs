//! wgpu plumbing: the device, buffers, shader composition and the stage shape.

pub mod buffers;
pub mod context;
pub mod engine;
pub mod inlet;
pub mod pipeline;
pub mod shader;
pub mod stage;
pub mod stages;
pub mod state;

pub use context::{AdapterSummary, GpuContext, GpuError};
