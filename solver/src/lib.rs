//! flume-solver: a GPU-resident weakly compressible SPH solver on wgpu (WGSL compute shaders),
//! the model of the flume digital twin. It knows nothing of ROS, DDS, MCAP or wall-clock time:
//! it takes a case and gives observations.
//!
//! Start at `gpu/pipeline.rs`: its step lists every stage; each stage name leads to its WGSL file
//! in `shaders/stages/`, its spec in `gpu/stages.rs` and its CPU oracle in `physics`.
//!
//! The API is what the crate root re-exports, plus `config` (the case file's types) and
//! `physics` (the reference model). The other public modules are internals, reachable only so
//! that the solver's own tests can drive single stages and compare them with their oracles.

// The API.

pub use backend::{Backend, CPU_BACKEND};
pub use config::{Case, ConfigError};
pub use derived::{Derived, check_inflow, derive, inflow_limit_m3_per_s, monaghan_alpha};
pub use engine::StageTime;
pub use error::SolverError;
pub use flume::BoundaryConditions;
pub use generate::generate;
pub use gpu::context::ADAPTER_ENV;
pub use gpu::{GpuContext, GpuError};
pub use health::{Culprit, Health, Recovery};
pub use observe::{
    BedInterfaces, FlumeObservation, GaugeReading, Observations, ProbeReading, ProfileColumn,
};
pub use particles::{ParticleRegion, Particles};
pub use physics::sediment::suspension::Region;
pub use simulation::{InflowSchedule, RefusedInflow, Simulation};

/// How an open flume's water sits on its bed: the cushion under the flow, the held bed's push.
pub mod bed_contact;
pub mod budget;
/// The case file's types: `Case` and its sections.
pub mod config;
/// The 1-D hydraulic reference for an open flume's steady levels (weir rating, backwater curve).
pub mod hydraulics;
/// The reference model: every formula once, called by both backends and by the O(N^2) oracle
/// that the tests compare them with.
pub mod physics;

mod backend;
mod cpu;
mod derived;
mod error;
mod flume;
mod health;
mod load;
mod observe;

// Internals that the solver's tests (`solver/tests/`) reach into: stage specs, uniform
// layouts, pipeline constants, the recovery policy, phase codes and parking spots, the
// generator's count, the inlet scan's reference. Hidden from the docs; not for the node.

/// The uniform blocks both engines run on, and their builder from a case.
#[doc(hidden)]
pub mod contract;
#[doc(hidden)]
pub mod engine;
#[doc(hidden)]
pub mod generate;
#[doc(hidden)]
pub mod gpu;
#[doc(hidden)]
pub mod particles;
#[doc(hidden)]
pub mod simulation;
/// The CPU backend's end of a step, which `tests/wgsl_store.rs` holds `store_rule.wgsl` to.
#[doc(hidden)]
pub use cpu::store::Store;
