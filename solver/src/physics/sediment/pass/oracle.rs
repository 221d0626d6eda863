//! The rheology pass particle by particle over every other, the oracle the backends' cell-list
//! passes are held to.

use super::{Draws, NO_FLUX, NO_TARGET, ParticleRheology, REGION_HELD, Rheology, SedimentModel};
use crate::physics::Params;

/// The rheology of every particle (see the module doc), `held_before[i]` whether particle i was
/// held after the previous pass; a pass without pick-up draws (particle i's id is i). In the
/// Drucker-Prager mode a particle held before stays held unless Shields makes it bed load: only
/// [`release_pass`](crate::physics::sediment::hold::release_pass), which follows this pass, releases it by the stress of its
/// neighbours.
///
/// Panics if the slices differ in length or a phase index is outside `params.phases` (bugs of
/// the caller).
pub fn rheology_pass(
    params: &Params,
    model: &SedimentModel,
    pos: &[[f32; 4]],
    vel_rho: &[[f32; 4]],
    held_before: &[bool],
) -> Vec<ParticleRheology> {
    let words: Vec<u32> = held_before
        .iter()
        .map(|&h| if h { REGION_HELD } else { 0 })
        .collect();
    rheology_pass_drawn(params, model, pos, vel_rho, &words, None)
}

/// [`rheology_pass`] from each particle's region word after the previous pass (its hold and,
/// under `van_rijn_integrated`, the mass picked up of it so far), with the pass's pick-up
/// `draws`, as the first pass of a step takes them.
pub fn rheology_pass_drawn(
    params: &Params,
    model: &SedimentModel,
    pos: &[[f32; 4]],
    vel_rho: &[[f32; 4]],
    words_before: &[u32],
    draws: Option<Draws>,
) -> Vec<ParticleRheology> {
    let none = (vec![NO_FLUX; pos.len()], vec![NO_TARGET; pos.len()]);
    let before = (words_before, none.0.as_slice(), none.1.as_slice());
    rheology_pass_exner(params, model, (pos, vel_rho), before, draws)
}

/// [`rheology_pass_drawn`] with the bed load each held particle at the surface passed on in
/// the last pass, `fluxes_before` ([`ParticleRheology::flux`]), and the particle it passed it
/// to, `targets_before` ([`ParticleRheology::target`]), on which `van_rijn_exner` settles it.
pub fn rheology_pass_exner(
    params: &Params,
    model: &SedimentModel,
    (pos, vel_rho): (&[[f32; 4]], &[[f32; 4]]),
    (words_before, fluxes_before, targets_before): (&[u32], &[f32], &[u32]),
    draws: Option<Draws>,
) -> Vec<ParticleRheology> {
    assert_eq!(pos.len(), vel_rho.len(), "positions and velocities differ");
    assert_eq!(pos.len(), words_before.len(), "positions and words differ");
    assert_eq!(
        (pos.len(), pos.len()),
        (fluxes_before.len(), targets_before.len()),
        "positions and fluxes differ"
    );
    let pass = Rheology::new(params, model).with_draws(draws);
    (0..pos.len())
        .map(|i| {
            let mut s = pass.start(&pos[i], &vel_rho[i]);
            for j in 0..pos.len() {
                pass.add_pair((&pos[i], &vel_rho[i]), (&pos[j], &vel_rho[j]), &mut s);
            }
            let exchange = pass
                .exchange_of((&pos[i], i as u32), &s, words_before[i])
                .map_or((0.0, NO_TARGET), |mut ex| {
                    for (j, x_j) in pos.iter().enumerate() {
                        ex.add(x_j, j as u32, (fluxes_before[j], targets_before[j]));
                    }
                    ex.outcome()
                });
            let before = (words_before[i], i as u32);
            pass.finish(&pos[i], &vel_rho[i], &s, before, exchange)
        })
        .collect()
}
