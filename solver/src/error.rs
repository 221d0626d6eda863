//! Why the solver refuses a case or stops a run: one error type for `Simulation` and both
//! backends, kept apart from `simulation.rs` so that the backends and the case checks can return
//! it without importing the module that drives them.

use crate::gpu::GpuError;
use crate::health::{self, Culprit, Health};

#[derive(Debug, thiserror::Error)]
pub enum SolverError {
    #[error(transparent)]
    Gpu(#[from] GpuError),
    #[error("the case has {0} particles; the solver's indices are 32-bit")]
    TooManyParticles(u64),
    #[error(
        "the case's neighbour grid has {0} cells; the solver's cell indices are 32-bit: use a coarser dp or a smaller domain"
    )]
    TooManyCells(u64),
    #[error(
        "simulation blew up at t = {time_s:.6} s (step {step}): {health}{}; worst particles: {}",
        recurring_cfl.map_or(String::new(), |c| format!(
            "; it recurred at about the same simulated time at every CFL down to {}: not a time-step problem",
            c as f32
        )),
        health::list(culprits)
    )]
    BlowUp {
        time_s: f64,
        step: u64,
        health: Health,
        /// The particles furthest from health when it failed (excluded ones first), worst first.
        culprits: Vec<Culprit>,
        /// The CFL number of a retry that failed at the same simulated time as the try before.
        recurring_cfl: Option<f64>,
    },
    #[error("cannot advance to t = {target_s} s: the simulation is already at {now_s} s")]
    TimeGoesBack { target_s: f64, now_s: f64 },
    #[error(
        "c0 = {c0_m_per_s:.3} m/s is too low for fluid {fluid_height_m} m high: at rest its density \
         is already {:.1} % off rest density (the bound is 10 %); use c0 above {c0_needed_m_per_s:.2} m/s \
         (coefsound 10 or more is usual)",
        100.0 * density_error
    )]
    SoundSpeedTooLow {
        c0_m_per_s: f64,
        fluid_height_m: f64,
        density_error: f64,
        c0_needed_m_per_s: f64,
    },
    #[error("the CPU backend cannot start its threads: {0}")]
    CpuThreads(String),
    #[error("parameter `{name}` refused: {reason}")]
    InvalidParameter { name: &'static str, reason: String },
}
