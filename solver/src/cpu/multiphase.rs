//! The water-sediment model's neighbour passes on the CPU backend (`rheology.wgsl`,
//! `yield_release.wgsl`): `physics::sediment`'s per-pair and per-particle functions over the
//! cell list, particles shared out among threads. A release reads the regions the rheology
//! pass left, before any release, so it does not depend on the order threads run.

use super::grid::Grid;
use crate::physics::Params;
use crate::physics::interaction::phase_index;
use crate::physics::sediment::hold::{Release, Transmitted};
use crate::physics::sediment::pass::{ParticleRheology, Rheology, SedimentModel};
use crate::physics::sediment::suspension::Region;
use rayon::prelude::*;

/// The rheology of the active particles (sorted order, `held_before[i]` from the last pass),
/// then, with `release`, the release of held sediment.
#[allow(clippy::too_many_arguments)]
pub fn rheology_pass(
    pool: &rayon::ThreadPool,
    params: &Params,
    model: &SedimentModel,
    grid: &Grid,
    pos: &[[f32; 4]],
    vel: &[[f32; 4]],
    held_before: &[bool],
    release: bool,
) -> Vec<ParticleRheology> {
    let pass = Rheology::new(params, model);
    let n = held_before.len();
    let vol: Vec<f32> = pool.install(|| {
        (0..n)
            .into_par_iter()
            .map(|i| pass.volume(&pos[i], &vel[i]))
            .collect()
    });
    let mut out: Vec<ParticleRheology> = pool.install(|| {
        (0..n)
            .into_par_iter()
            .map(|i| {
                let me = (&pos[i], &vel[i]);
                let mut s = pass.start(me.0, me.1);
                // A wall's rheology is none whatever its neighbours.
                if params.phases[phase_index(me.0)].mobile {
                    grid.rows(grid.coords(&[pos[i][0], pos[i][1], pos[i][2]]), |range| {
                        for j in range {
                            pass.add_pair_of_volume(me, (&pos[j], &vel[j]), vol[j], &mut s);
                        }
                    });
                }
                pass.finish(me.0, me.1, &s, held_before[i])
            })
            .collect()
    });
    if release {
        let stage = Release::new(params, model);
        let released: Vec<bool> = pool.install(|| {
            (0..out.len())
                .into_par_iter()
                .map(|i| {
                    if !stage.applies(&pos[i], &out[i]) {
                        return false;
                    }
                    let mut sums = Transmitted::default();
                    grid.rows(grid.coords(&[pos[i][0], pos[i][1], pos[i][2]]), |range| {
                        for j in range {
                            stage.add_pair(&pos[i], (&pos[j], &vel[j], &out[j]), &mut sums);
                        }
                    });
                    stage.released(vel[i][3], &sums)
                })
                .collect()
        });
        for (r, _) in out.iter_mut().zip(released).filter(|(_, go)| *go) {
            r.held = false;
            r.region = Region::Yielded as u32;
        }
    }
    out
}
