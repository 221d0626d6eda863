//! The erosion chain of each grain as the rheology pass works it out: what a researcher looks
//! at to see why a grain eroded, and what the tests check against an oracle of their own.

use super::Simulation;
use crate::particles::Particles;
use crate::physics::sediment::pass::{Rheology, ShieldsChain};

impl Simulation {
    /// The Shields chain ([`ShieldsChain`]) of every sediment particle of `particles` (in id
    /// order, as [`Simulation::read_particles`] gives them), by index: the sums of the rheology
    /// pass over every other particle by brute force, then its Shields step, both the code the
    /// CPU backend runs. None for a case without a sediment.
    pub fn shields_chains(&self, particles: &Particles) -> Option<Vec<(usize, ShieldsChain)>> {
        let model = crate::contract::sediment_model(&self.case, &self.derived)?;
        let params = self
            .params
            .physics(self.case.dimension, self.derived.phases.len());
        let pass = Rheology::new(&params, &model);
        let sediment = model.sediment_phase as u32;
        let (pos, vel) = (&particles.positions, &particles.vel_rho);
        let chains = (0..particles.len())
            .filter(|&i| particles.phase(i) == sediment)
            .map(|i| {
                let mut sums = pass.start(&pos[i], &vel[i]);
                for j in (0..particles.len()).filter(|&j| j != i) {
                    pass.add_pair((&pos[i], &vel[i]), (&pos[j], &vel[j]), &mut sums);
                }
                (i, pass.shields_chain(&sums))
            })
            .collect();
        Some(chains)
    }
}
