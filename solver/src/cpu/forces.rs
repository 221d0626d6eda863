//! The force pass of the CPU backend: each particle sums its neighbours' pair terms
//! (`PairModel::add_pair`, the one statement of the formulas) over the contiguous rows of the
//! cell list, particles shared out among threads in blocks. Each sum is taken by one thread in
//! sorted order, so the result does not depend on the number of threads.

use super::grid::Grid;
use crate::physics::interaction::{PairModel, PairSum, Side};
use rayon::prelude::*;

/// Particles per block handed to a thread: large enough to amortise the hand-out, small
/// enough to balance a flume whose particles crowd in a few cells.
const BLOCK: usize = 512;

/// Fills `forces` (`[ax, ay, az, d rho/dt]`) and `dt_limit` (the stable step before the CFL
/// factor) of each particle of `sides`, in sorted order; cells come from `grid`, whose
/// starts were sorted from the same particles or from the state half a step before.
pub fn force_pass(
    pool: &rayon::ThreadPool,
    model: &PairModel,
    grid: &Grid,
    sides: &[Side],
    forces: &mut [[f32; 4]],
    dt_limit: &mut [f32],
) {
    pool.install(|| {
        forces
            .par_chunks_mut(BLOCK)
            .zip(dt_limit.par_chunks_mut(BLOCK))
            .enumerate()
            .for_each(|(block, (forces, dt_limit))| {
                let first = block * BLOCK;
                for (k, (f, dt)) in forces.iter_mut().zip(dt_limit).enumerate() {
                    let side = &sides[first + k];
                    let mut sum = PairSum::default();
                    grid.rows(grid.coords(&side.x), |range| {
                        for other in &sides[range] {
                            model.add_pair(side, other, &mut sum);
                        }
                    });
                    (*f, *dt) = model.finish(side, &sum, true);
                }
            });
    });
}

/// The smallest stable step over particles, s (f32::MAX when none bounds it, as the GPU's
/// reduction starts).
pub fn min_dt(dt_limit: &[f32]) -> f32 {
    dt_limit.iter().copied().fold(f32::MAX, f32::min)
}
