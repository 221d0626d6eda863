//! What `Simulation` asks of a backend: the particle state and the step loop, behind one trait.
//! The wgpu backend (`gpu::engine`) and the native CPU backend (`cpu`) run the same stages in
//! the same order on the same uniform (`SimParams`) and the same step state (`StepState`), so
//! time keeping, recovery, the open flume's host side and observations stay in one place.

use crate::contract::{Extremes, SimParams, StepState};
use crate::error::SolverError;

/// The state as the backend stores it: positions, velocity-density and ids, each in the
/// backend's own order (the cell order of the last step).
pub struct RawState {
    pub positions: Vec<[f32; 4]>,
    pub vel_rho: Vec<[f32; 4]>,
    pub ids: Vec<u32>,
}

/// What the open flume's inlet finds before it fills its new columns (`Engine::inlet_scan`).
#[derive(Debug, Clone, PartialEq)]
pub struct InletScan {
    /// Per spot, whether a particle that is not parked is nearer to it than the radius.
    pub occupied: Vec<bool>,
    /// Storage slots (as `read_state` orders them) of parked particles, lowest id first, one
    /// per spot at most.
    pub parked_slots: Vec<usize>,
}

/// `Engine::inlet_scan` over the whole state, in storage order: the CPU backend's, and the
/// reference of `inlet_scan.wgsl` (the same f32 test of the squared distance in x and y).
pub fn inlet_scan(
    positions: &[[f32; 4]],
    ids: &[u32],
    parked_phase: u32,
    spots: &[[f32; 2]],
    radius: f32,
) -> InletScan {
    let r2 = radius * radius;
    let occupied = spots
        .iter()
        .map(|s| {
            positions.iter().any(|p| {
                let (dx, dy) = (p[0] - s[0], p[1] - s[1]);
                p[3].to_bits() != parked_phase && dx * dx + dy * dy < r2
            })
        })
        .collect();
    let mut parked_slots = crate::flume::parked_slots(positions, ids, parked_phase);
    parked_slots.truncate(spots.len());
    InletScan {
        occupied,
        parked_slots,
    }
}

/// Time spent in one stage, summed over the steps since the engine was built, and the
/// particles its neighbour passes took (zero for a stage without one), of which `asleep` were
/// spared their neighbour loop.
#[derive(Clone, Debug, PartialEq)]
pub struct StageTime {
    pub stage: &'static str,
    pub seconds: f64,
    /// Of `seconds`, those in the parallel walk over the neighbours and each particle's own
    /// work after it; the rest is the set-up and book-keeping around it (the sides, the
    /// awake set's flags, what is stored by id), much of it on one thread.
    pub walk_seconds: f64,
    pub particles: u64,
    pub asleep: u64,
    /// Lane-pairs its neighbour walks evaluated while counted (`Engine::count_lanes`), and
    /// those of them that added to a sum read.
    pub lane_pairs: u64,
    pub useful_pairs: u64,
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
    /// For the open flume's inlet: which of `spots` (x, y, m) a particle that is not parked is
    /// nearer to than `radius`, and the slots of parked particles to place there, without
    /// reading the whole state back.
    fn inlet_scan(&mut self, spots: &[[f32; 2]], radius: f32) -> Result<InletScan, SolverError>;
    /// Region words by particle id (see `Simulation::regions`).
    fn regions(&self) -> Result<Vec<u32>, SolverError>;
    /// Sets the region words by particle id, one a particle, as the next pass reads them.
    fn write_regions(&mut self, words: &[u32]);
    /// Forces of the current state by particle id, and the smallest stable step over
    /// particles before the CFL factor, without advancing.
    fn forces(&mut self) -> Result<(Vec<[f32; 4]>, f32), SolverError>;
    /// The cell list of the current state: (cell starts, ids in sorted order).
    fn cell_list(&self) -> Result<(Vec<u32>, Vec<u32>), SolverError>;
    /// Probe sums at the probe points (pressure, fullness of phases 1-3) and the extremes.
    fn observe(&self) -> Result<(Vec<[f32; 4]>, Extremes), SolverError>;
    /// Time per stage so far; empty where the backend cannot time its stages apart.
    fn stage_times(&self) -> Vec<StageTime>;
    /// Counts the lane-pairs of each force pass from now (`on`) or no longer: a second walk
    /// over the neighbours, for `bench`. Backends without lanes ignore it.
    fn count_lanes(&mut self, _on: bool) {}
}

/// Which optional stages a case's pipeline has.
#[derive(Clone, Copy, Debug)]
pub struct PipelineShape {
    pub dim: u32,
    pub divisions: u32,
    pub verlet: bool,
    pub multiphase: bool,
    /// The hold stage, which releases held sediment that yields (Drucker-Prager).
    pub hold: bool,
}

/// Particles listed in storage order, reordered by id (index i holds the particle of id i).
pub fn by_id<T: Copy + Default>(values: &[T], ids: &[u32]) -> Vec<T> {
    let mut out = vec![T::default(); values.len()];
    for (v, &id) in values.iter().zip(ids) {
        if let Some(slot) = out.get_mut(id as usize) {
            *slot = *v;
        }
    }
    out
}
