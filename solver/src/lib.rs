//! flume-solver: a GPU-resident weakly compressible SPH solver on wgpu (WGSL compute shaders),
//! the model of the flume digital twin. It knows nothing of ROS, DDS, MCAP or wall-clock time:
//! it takes a case and gives observations.
//!
//! Start at `pipeline.rs`: its step lists every stage; each stage name leads to its WGSL file
//! in `shaders/stages/`, its spec in `stages.rs` and its CPU oracle in `physics`.

pub mod backend;
pub mod config;
pub mod cpu;
pub mod derived;
pub mod engine;
pub mod error;
pub mod flume;
pub mod generate;
pub mod gpu;
pub mod health;
mod load;
pub mod observe;
pub mod particles;
pub mod physics;
pub mod pipeline;
pub mod simulation;
pub mod stages;
pub mod uniform;

pub use backend::Backend;
pub use config::{Case, ConfigError};
pub use derived::{MAX_INLET_MACH, check_inflow, derive};
pub use error::SolverError;
pub use flume::BoundaryConditions;
pub use generate::generate;
pub use gpu::{GpuContext, GpuError};
pub use observe::{Observations, ProfileColumn};
pub use particles::Particles;
pub use simulation::{Health, Recovery, Simulation};
