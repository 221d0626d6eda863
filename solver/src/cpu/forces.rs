//! The force pass of the CPU backend: each particle sums its neighbours' pair terms
//! (`PairModel::add_pair`, the one statement of the formulas) over the contiguous rows of the
//! cell list, particles shared out among threads in blocks. Each sum is taken by one thread in
//! sorted order, so the result does not depend on the number of threads.

use super::grid::Grid;
use crate::physics::interaction::{PairModel, PairSum, Side};
use crate::physics::sediment::pass::{StressDivergence, StressSide};
use crate::physics::timestep::particle_viscous_bound;
use rayon::prelude::*;

/// Particles per block handed to a thread: large enough to amortise the hand-out, small
/// enough to balance a flume whose particles crowd in a few cells.
const BLOCK: usize = 512;

/// What the force pass reads besides the particles' sides.
pub struct Extra<'a> {
    /// The multiphase model's stress divergence, with the stress side and apparent viscosity
    /// of each particle (its explicit viscous bound joins the step).
    pub stress: Option<(&'a StressDivergence<'a>, &'a [StressSide], &'a [f32])>,
    /// Particles whose velocity is imposed (an open flume's inlet buffer and duct): their
    /// acceleration does not bound the step. Empty: none.
    pub imposed: &'a [bool],
}

/// Fills `forces` (`[ax, ay, az, d rho/dt]`) and `dt_limit` (the stable step before the CFL
/// factor) of each particle of `sides`, in sorted order; cells come from `grid`, whose
/// starts were sorted from the same particles or from the state half a step before.
pub fn force_pass(
    pool: &rayon::ThreadPool,
    model: &PairModel,
    grid: &Grid,
    sides: &[Side],
    extra: &Extra,
    forces: &mut [[f32; 4]],
    dt_limit: &mut [f32],
) {
    let h = model.params().h;
    pool.install(|| {
        forces
            .par_chunks_mut(BLOCK)
            .zip(dt_limit.par_chunks_mut(BLOCK))
            .enumerate()
            .for_each(|(block, (forces, dt_limit))| {
                let first = block * BLOCK;
                for (k, (f, dt)) in forces.iter_mut().zip(dt_limit).enumerate() {
                    let i = first + k;
                    let side = &sides[i];
                    let mut sum = PairSum::default();
                    let mut tau = [0.0f32; 3];
                    grid.rows(grid.coords(&side.x), |range| match extra.stress {
                        None => {
                            for j in range {
                                model.add_pair(side, &sides[j], &mut sum);
                            }
                        }
                        Some((div, stress, _)) => {
                            for j in range {
                                if let Some(g) = model.add_pair(side, &sides[j], &mut sum) {
                                    div.add_term(&stress[i], &stress[j], &g, &mut tau);
                                }
                            }
                        }
                    });
                    for (a, t) in sum.acc.iter_mut().zip(tau) {
                        *a += t;
                    }
                    let imposed = extra.imposed.get(i).copied().unwrap_or(false);
                    (*f, *dt) = model.finish(side, &sum, !imposed);
                    if let Some((_, _, mu)) = extra.stress
                        && dt.is_finite()
                    {
                        *dt = dt.min(particle_viscous_bound(h, side.rho, mu[i]));
                    }
                }
            });
    });
}

/// The smallest stable step over particles, s (f32::MAX when none bounds it, as the GPU's
/// reduction starts).
pub fn min_dt(dt_limit: &[f32]) -> f32 {
    dt_limit.iter().copied().fold(f32::MAX, f32::min)
}
