//! What `Simulation` asks of a backend: the particle state and the step loop, behind one trait.
//! The wgpu backend (`gpu::engine`) and the native CPU backend (`cpu`) run the same stages in
//! the same order on the same uniform (`SimParams`) and the same step state (`StepState`), so
//! time keeping, recovery, the open flume's host side and observations stay in one place.

use crate::error::SolverError;
use crate::gpu::params::{Extremes, SimParams, StepState};

/// The state as the backend stores it: positions, velocity-density and ids, each in the
/// backend's own order (the cell order of the last step).
pub struct RawState {
    pub positions: Vec<[f32; 4]>,
    pub vel_rho: Vec<[f32; 4]>,
    pub ids: Vec<u32>,
}

/// Time spent in one stage, summed over the steps since the engine was built.
#[derive(Clone, Debug, PartialEq)]
pub struct StageTime {
    pub stage: &'static str,
    pub seconds: f64,
}

pub trait Engine: Send {
    /// The backend and device, as the start-up line and `/diagnostics` name them.
    fn name(&self) -> String;
    /// Takes the uniform in force from the next step on.
    fn write_params(&mut self, params: &SimParams);
    /// Keeps a copy of the state (and the holds) to come back to after a blow-up.
    fn save(&mut self);
    /// Goes back to the last saved copy.
    fn restore(&mut self);
    /// Runs up to `steps` steps from the step state `init` and returns the step state after
    /// them; a step past the chunk's end or after a failed health check does nothing.
    fn run(&mut self, init: StepState, steps: u32) -> Result<StepState, SolverError>;
    fn read_state(&self) -> Result<RawState, SolverError>;
    /// Puts a particle into storage slot `slot` (as `read_state` orders it), at rest in both
    /// of Verlet's sequences: the open flume's inlet.
    fn place(&mut self, slot: usize, position: [f32; 4], vel_rho: [f32; 4]);
    /// Region words by particle id (see `Simulation::regions`).
    fn regions(&self) -> Result<Vec<u32>, SolverError>;
    /// Forces of the current state by particle id, and the smallest stable step over
    /// particles before the CFL factor, without advancing.
    fn forces(&mut self) -> Result<(Vec<[f32; 4]>, f32), SolverError>;
    /// The cell list of the current state: (cell starts, ids in sorted order).
    fn cell_list(&self) -> Result<(Vec<u32>, Vec<u32>), SolverError>;
    /// Probe sums at the probe points (pressure, fullness of phases 1-3) and the extremes.
    fn observe(&self) -> Result<(Vec<[f32; 4]>, Extremes), SolverError>;
    /// Time per stage so far; empty where the backend cannot time its stages apart.
    fn stage_times(&self) -> Vec<StageTime>;
}
