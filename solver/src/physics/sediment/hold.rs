//! Un-yielded sediment held at rest, and released by the stress its moving neighbours transmit
//! (the Drucker-Prager mode's answer to the creep of a capped viscosity).
//!
//! The paper keeps region 1 static through its HBP viscosity `tau_y m`, tens of thousands of
//! Pa s for the Louvain bed. An explicit scheme is stable only for `dt <= 0.125 h^2 rho / mu`:
//! at dp = 5 mm that is about 1e-6 s against the acoustic 1e-4 s, a hundred times the steps.
//! Capping the viscosity (`SedimentModel::mu_max`) keeps the step and turns the bed into a
//! liquid of tens of Pa s that a dam-break wave shears down to the floor, the "excessive
//! creeping resulting from a fluid model" of the paper's Fig. 12. So, as Manenti et al. (2012)
//! and the paper's own Shields-only mode do, un-yielded sediment is held fixed; unlike them the
//! hold is released where Drucker-Prager says the particle yields.
//!
//! The test needs the particle's shear stress. A held particle has no strain rate of its own
//! that measures it: at rest between moving neighbours its strain rate is theirs, at rest
//! among held ones it is zero whatever the load. Its stress is what the sediment moving next
//! to it carries, continuous across the interface as momentum balance requires. So:
//! - a sediment particle that moves is classified by the stress it carries (Eq. 30 on
//!   `2 mu eps` with the capped viscosity, as before the hold), and held when that says it is
//!   un-yielded;
//! - a held particle stays held unless Shields makes it bed load (Eq. 25) or the stress
//!   transmitted by its moving sediment neighbours (their Shepard average,
//!   `sum_j V_j W_ij tau_j / sum_j V_j W_ij`) exceeds the stress at which its own HBP law
//!   flows, [`FLOW_ONSET`] times its yield stress (Eqs. 15, 30-31). The yield stress grows with
//!   the skeleton pressure, so the release stops at the depth where the transmitted stress
//!   falls below it: the boundary between regions 1 and 2 comes from Eq. 31, not from a fixed
//!   depth.
//!
//! Why twice the yield stress and not Eq. 30's `sqrt(J2) > tau_y`: Eq. 15 as written
//! (`tau = 2 mu eps`) makes a flowing particle carry `sqrt(J2) = 2 tau_y (1 - exp(-m s)) + ...`,
//! at least 2 tau_y once `m s >> 1` (the `rheology` module doc). In the paper's uncapped model
//! a particle loaded between tau_y and 2 tau_y is "yielded" but creeps at `s < ~3 / m`,
//! 0.03 1/s for the Louvain bed: it stays where it is. Released at tau_y instead, a particle
//! flows and transmits 2 tau_y of its own to the one below, whose yield stress is larger by
//! only a factor `1 + dp / depth`: the release runs down to the floor whatever the load (seen
//! on the Louvain case at dp = 5 mm: the bottom row at the gate slid 54 mm on average by
//! t = 0.25 s).
//! Once moving, a particle is held again when the stress it carries falls below tau_y itself:
//! it takes twice the stress to start the bed as to keep it going, static friction above
//! dynamic, as in a granular bed.
//!
//! Held particles keep their viscous stress `2 mu eps` in the force pass: a moving neighbour is
//! dragged by them as by the slow bed of the unheld model. The GPU's
//! `shaders/stages/hold.wgsl` must give the same regions.

use super::drucker_prager::{alpha, kappa_c, skeleton_pressure, yield_stress, yields};
use super::pass::{ParticleRheology, SedimentModel};
use super::rheology::{Tensor3, second_invariant};
use super::suspension::Region;
use crate::physics::Params;
use crate::physics::eos::{pressure, tait_b};
use crate::physics::interaction::phase_index;
use crate::physics::kernel::Wendland;

/// Shepard average `sum_j weight_j tau_j / sum_j weight_j` of the stresses of the moving
/// neighbours, Pa; `None` when no weight is positive (nothing moves next to the particle).
pub fn transmitted_stress(weights: &[f32], stresses: &[Tensor3]) -> Option<Tensor3> {
    assert_eq!(weights.len(), stresses.len(), "weights and stresses differ");
    let mut sums = Transmitted::default();
    for (&w, t) in weights.iter().zip(stresses) {
        sums.add(w, t);
    }
    sums.mean()
}

/// The running sums of [`transmitted_stress`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Transmitted {
    weight: f32,
    tau: Tensor3,
}

impl Transmitted {
    pub fn add(&mut self, weight: f32, tau: &Tensor3) {
        self.weight += weight;
        for (row, t_row) in self.tau.iter_mut().zip(tau) {
            for (x, t) in row.iter_mut().zip(t_row) {
                *x += weight * t;
            }
        }
    }

    pub fn mean(&self) -> Option<Tensor3> {
        if self.weight.is_nan() || self.weight <= 0.0 {
            return None;
        }
        let mut tau = self.tau;
        for row in &mut tau {
            for x in row {
                *x /= self.weight;
            }
        }
        Some(tau)
    }
}

/// The stress invariant at which Eq. 15 (as written) lets sediment of yield stress tau_y flow,
/// in units of tau_y: `sqrt(J2) = 2 mu sqrt(II_D) -> 2 tau_y` as `m sqrt(II_D)` grows.
pub const FLOW_ONSET: f32 = 2.0;

/// Whether a held particle of yield stress `tau_y` (Pa) is released by the transmitted stress
/// `tau`: its invariant `sqrt(J2)` exceeds `FLOW_ONSET tau_y` (Eq. 30 with Eq. 15's onset).
pub fn released(tau: &Tensor3, tau_y: f32) -> bool {
    yields(second_invariant(tau).sqrt(), FLOW_ONSET * tau_y)
}

/// The release stage of one run: [`Release::add_pair`] and [`Release::released`] are the one
/// statement of it, which the brute-force [`release_pass`] and the CPU backend both call.
#[derive(Clone, Debug)]
pub struct Release<'a> {
    model: &'a SedimentModel,
    kernel: Wendland,
    support2: f32,
    /// Mass, rest density and Tait stiffness of the sediment.
    sediment: (f32, f32, f32),
    alpha_dp: f32,
    kappa_dp: f32,
}

impl<'a> Release<'a> {
    pub fn new(params: &Params, model: &'a SedimentModel) -> Release<'a> {
        let mat = &model.material;
        let sed = &params.phases[model.sediment_phase];
        Release {
            model,
            kernel: Wendland::new(params.h, params.dim),
            support2: 4.0 * params.h * params.h,
            sediment: (sed.mass, sed.rho0, tait_b(params.c0, sed.rho0)),
            alpha_dp: alpha(mat.phi_rad),
            kappa_dp: kappa_c(mat.phi_rad, mat.cohesion_pa),
        }
    }

    /// Whether the release decides on particle `x` of this rheology: held sediment.
    pub fn applies(&self, x: &[f32; 4], rheology: &ParticleRheology) -> bool {
        !self.model.shields_only && rheology.held && phase_index(x) == self.model.sediment_phase
    }

    /// The units a particle released with `units` worn off it keeps: under Exner's balance
    /// all of them, which went downstream as bed load; by the pick-up alone none, as it is
    /// released whole.
    pub fn carried(&self, units: i32) -> i32 {
        if self.model.exner() { units } else { 0 }
    }

    /// Whether particle `x` of this rheology transmits stress to the held sediment around it:
    /// moving sediment.
    #[inline(always)]
    pub fn transmits(&self, x: &[f32; 4], rheology: &ParticleRheology) -> bool {
        !rheology.held && phase_index(x) == self.model.sediment_phase
    }

    /// Adds neighbour j (position, velocity-density, rheology) to a held particle at `x_i`:
    /// only moving sediment within the support counts.
    #[inline(always)]
    pub fn add_pair(
        &self,
        x_i: &[f32; 4],
        (x_j, v_j, r_j): (&[f32; 4], &[f32; 4], &ParticleRheology),
        sums: &mut Transmitted,
    ) {
        if !self.transmits(x_j, r_j) {
            return;
        }
        let r2: f32 = (0..3).map(|k| (x_i[k] - x_j[k]).powi(2)).sum();
        if r2 < self.support2 {
            let v = self.sediment.0 / v_j[3];
            sums.add(v * self.kernel.w(r2.sqrt()), &r_j.stress);
        }
    }

    /// Whether a held particle of density `rho_i` with these sums is released.
    pub fn released(&self, rho_i: f32, sums: &Transmitted) -> bool {
        let (_, rho0, b) = self.sediment;
        let mat = &self.model.material;
        let p = pressure(rho_i, rho0, b);
        let tau_y = yield_stress(
            self.alpha_dp,
            self.kappa_dp,
            skeleton_pressure(p, mat.rho_s, mat.rho_w),
        );
        sums.mean().is_some_and(|t| released(&t, tau_y))
    }
}

/// Releases the held sediment that its moving neighbours make yield (see the module doc), in
/// place: a released particle becomes region 2 and not held. Which neighbours move is read from
/// `rheology` as the rheology pass left it, before any release, so the result does not depend
/// on the order particles are visited. Shields-only runs are left as they are.
///
/// Panics if the slices differ in length (a bug of the caller).
pub fn release_pass(
    params: &Params,
    model: &SedimentModel,
    pos: &[[f32; 4]],
    vel_rho: &[[f32; 4]],
    rheology: &mut [ParticleRheology],
) {
    assert_eq!(pos.len(), vel_rho.len(), "positions and velocities differ");
    assert_eq!(pos.len(), rheology.len(), "positions and rheology differ");
    let stage = Release::new(params, model);
    let release: Vec<usize> = (0..pos.len())
        .filter(|&i| stage.applies(&pos[i], &rheology[i]))
        .filter(|&i| {
            let mut sums = Transmitted::default();
            for j in 0..pos.len() {
                stage.add_pair(&pos[i], (&pos[j], &vel_rho[j], &rheology[j]), &mut sums);
            }
            stage.released(vel_rho[i][3], &sums)
        })
        .collect();
    for i in release {
        rheology[i].held = false;
        rheology[i].region = Region::Yielded as u32;
        rheology[i].pickup = stage.carried(rheology[i].pickup);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn shear(t: f32) -> Tensor3 {
        [[0.0, t, 0.0], [t, 0.0, 0.0], [0.0, 0.0, 0.0]]
    }

    #[test]
    fn transmitted_stress_is_the_weighted_mean() {
        // Weights 1 and 3 on shear stresses 10 and 30 Pa: (10 + 90) / 4 = 25 Pa.
        let t = transmitted_stress(&[1.0, 3.0], &[shear(10.0), shear(30.0)]).expect("weights");
        assert_eq!(t[0][1], 25.0);
        assert_eq!(t[1][0], 25.0);
        assert_eq!(t[0][0], 0.0);
        assert!(transmitted_stress(&[], &[]).is_none());
        assert!(transmitted_stress(&[0.0], &[shear(1.0)]).is_none());
    }

    #[test]
    fn released_above_the_yield_stress_only() {
        // Simple shear t: J2 = 1/2 (t^2 + t^2) = t^2, so sqrt(J2) = t; the onset is 2 tau_y.
        assert!(released(&shear(20.5), 10.0));
        assert!(!released(&shear(20.0), 10.0));
        assert!(!released(&shear(15.0), 10.0));
        assert!(!released(&shear(-19.0), 10.0));
        // Cohesionless sand at zero skeleton pressure gives way to any shear.
        assert!(released(&shear(1e-6), 0.0));
    }
}
