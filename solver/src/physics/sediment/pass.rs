//! The rheology pass of the water-sediment model, brute force over all pairs: for every particle
//! its strain rate, region and apparent viscosity, hence its viscous stress `tau = 2 mu eps`
//! (Eqs. 11-15, 26-33, Figure 2); then the stress divergence of the momentum equation (Eq. 10).
//! The GPU's `shaders/stages/rheology.wgsl` and the multiphase branch of `interaction.wgsl`
//! must give the same numbers (up to summation order).
//!
//! Choices the paper leaves open, each stated where it is made:
//! - the skeleton pressure of Drucker-Prager ([`skeleton_pressure`]);
//! - what the Shields-only mode does with a sediment particle that is neither eroded nor inside
//!   the bed ([`classify_shields_only`](super::suspension::classify_shields_only));
//! - the cap on the apparent viscosity ([`SedimentModel::mu_max`]), and the hold of
//!   un-yielded sediment that makes up for it ([`super::hold`]);
//! - the bed slope, from the bed's outward normal ([`slope_factors`]): the gradient of the solid
//!   around the grain (sediment and walls), `-sum_solid V_j grad_i W_ij`. The paper does not say
//!   which normal; one taken from the water, `sum_water V_j grad_i W_ij`, leans wherever the
//!   water covers the kernel on one side only, as at the tip of a sheet one particle thick over
//!   a flat bed, and past the friction angle it gave a critical stress of zero (on the CI flume,
//!   1,767 of the first 6 s' 1,922 pick-ups).

use super::SedimentParams;
use super::drucker_prager::{alpha, kappa_c, skeleton_pressure, yield_stress};
use super::pickup::{units_word, word_units};
use super::rheology::{Tensor3, hbp_viscosity, second_invariant, sps_viscosity, strain_rate};
use super::shields::{
    bed_shear_stress, critical_bed_shear_stress, critical_shields, friction_velocity,
    slope_factors, sloped_critical_stress,
};
use super::suspension::{
    Region, RegionInputs, apparent_viscosity, level_solid, sediment_region, volume_fraction,
};
use crate::physics::eos::{pressure, tait_b};
use crate::physics::interaction::phase_index;
use crate::physics::kernel::Wendland;
use crate::physics::lanes::{Mask, Real};
use crate::physics::{Params, Viscosity};

/// The sediment model of one run.
#[derive(Clone, Debug, PartialEq)]
pub struct SedimentModel {
    pub material: SedimentParams,
    /// Index in `Params::phases` of the sediment and of the water.
    pub sediment_phase: usize,
    pub water_phase: usize,
    /// The paper's Shields-only mode: sediment that is neither eroded nor suspended is held
    /// fixed, and Drucker-Prager is not used. Otherwise un-yielded sediment is held until
    /// Drucker-Prager releases it ([`super::hold`]).
    pub shields_only: bool,
    /// The Shields test reads the nearest water particle's own velocity, not its velocity
    /// relative to the grain (`config::ShieldsSpeed`).
    pub water_speed: bool,
    /// A moving grain is held again only with a solid beside it at its own level
    /// (`config::ComesToRest::BesideASolid`).
    pub rests_beside_solid: bool,
    /// Largest apparent viscosity, Pa s, of the stress a particle carries. An explicit scheme
    /// is stable for `dt <= 0.125 h^2 rho / mu`; the un-yielded HBP viscosity (tau_y m, tens of
    /// thousands of Pa s for the Louvain bed) would need steps 10^2 to 10^3 times shorter than
    /// the acoustic ones.
    pub mu_max: f32,
    /// van Rijn's pick-up rate per unit `T^1.5`, 1/s ([`super::pickup`]); 0: Shields releases a
    /// particle at once, as the paper does.
    pub pickup_per_s: f32,
    /// A held particle leaves once the pick-up rate's integral has taken its mass
    /// ([`super::pickup::integrated_pickup`]), not by a chance each step.
    pub pickup_integrated: bool,
    /// van Rijn's (1984a) saltation length per unit `T^0.9` over dp: with it, what is worn off
    /// a held particle is net of the bed load that settles on it from upstream
    /// (`van_rijn_exner`, [`super::pickup::exner_pickup`]); 0: the pick-up alone wears it.
    pub exner_step_per_stage: f32,
    /// The particle spacing, m: the held particle upstream of another lies about dp up the flow.
    pub dp_m: f32,
}

impl SedimentModel {
    /// Whether a held particle is worn net of the bed load that settles on it
    /// (`van_rijn_exner`).
    pub fn exner(&self) -> bool {
        self.exner_step_per_stage > 0.0
    }

    /// This model worn by van Rijn's pick-up on a bed of particles 1 cm apart in water of
    /// kinematic viscosity 1e-6 m2/s (`van_rijn_exner` with `exner`, else
    /// `van_rijn_integrated`), the Shields test on the water's speed: the unit tests' bed.
    #[cfg(test)]
    pub(crate) fn worn_by_van_rijn(self, exner: bool) -> SedimentModel {
        use super::pickup::{pickup_per_s, saltation_length_per_stage};
        let (dp, nu_w) = (0.01, 1e-6);
        let m = &self.material;
        let (rho_s, rho_w, d50) = (f64::from(m.rho_s), f64::from(m.rho_w), f64::from(m.d50_m));
        let step = saltation_length_per_stage(d50, rho_s, rho_w, nu_w, 9.81) / dp;
        SedimentModel {
            water_speed: true,
            pickup_per_s: pickup_per_s(d50, rho_s, rho_w, nu_w, 9.81, dp) as f32,
            pickup_integrated: true,
            exner_step_per_stage: if exner { step as f32 } else { 0.0 },
            ..self
        }
    }
}

/// The pick-up draw of a rheology pass: the run's step count (wrapping) and the last step's
/// length, s. One pass a step draws (the one before the step's size is chosen), so a symplectic
/// step's second pass takes none.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Draws {
    pub step: u32,
    pub dt_s: f32,
}

/// What the rheology pass gives one particle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ParticleRheology {
    /// Viscous stress `tau = 2 mu eps`, Pa; zero for walls.
    pub stress: Tensor3,
    /// Apparent viscosity, Pa s (after the cap); zero for walls.
    pub mu: f32,
    /// Region 1-5 of Figure 2 (5 for water), 0 for walls.
    pub region: u32,
    /// Held fixed this step: un-yielded sediment (region 1).
    pub held: bool,
    /// The share of a held particle's mass the flow has picked up so far, in
    /// [`PICKUP_WHOLE`](super::pickup::PICKUP_WHOLE)ths (`van_rijn_integrated`), or in
    /// [`EXNER_WHOLE`](super::pickup::EXNER_WHOLE)ths net of what settled on it, negative where
    /// that is more than was worn off (`van_rijn_exner`); 0 otherwise.
    pub pickup: i32,
    /// The bed load a held particle at the bed's top, wet or dry, passes on downstream, particles per
    /// second (`van_rijn_exner`, [`super::pickup::exner_exchange`] in a pass with draws, else
    /// [`super::pickup::bed_load_flux`]); [`NO_FLUX`] for any other.
    /// The pass's, before any release by the stress of its neighbours (`hold.wgsl` leaves it).
    pub flux: f32,
    /// The id of the particle it passes that load to ([`NO_TARGET`]: none, or off the bed).
    pub target: u32,
}

/// The flux of a particle that is not held at the bed's top, or of a pass without
/// deposition: no particle downstream reads it.
pub const NO_FLUX: f32 = -1.0;

/// Bit of a region word marking sediment held fixed; `REGION_HELD` of
/// `shaders/common/sediment.wgsl` too (checked by `shaders_validate`).
pub const REGION_HELD: u32 = 256;

impl ParticleRheology {
    /// A wall's rheology: no stress, no viscosity, no region, not held, no bed load.
    pub const NONE: ParticleRheology = ParticleRheology {
        stress: [[0.0; 3]; 3],
        mu: 0.0,
        region: 0,
        held: false,
        pickup: 0,
        flux: NO_FLUX,
        target: NO_TARGET,
    };

    /// The region word the backends store per particle: the region, `REGION_HELD`, and above
    /// them the mass picked up so far.
    pub fn word(&self) -> u32 {
        self.region | if self.held { REGION_HELD } else { 0 } | units_word(self.pickup)
    }
}

fn norm3(a: [f32; 3]) -> f32 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}

/// The Shields chain of one sediment particle ([`Rheology::shields_chain`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShieldsChain {
    /// Eq. 26: a water particle within the support and a kernel mass of sediment below the
    /// surface fraction of a particle's.
    pub at_surface: bool,
    /// Distance to the nearest water particle, m (infinite with none): the z of the log law.
    pub z_m: f32,
    /// That water particle's speed, relative to this one or its own, m/s: the u of the log law.
    pub speed_m_per_s: f32,
    pub u_star_m_per_s: f32,
    /// Bed shear stress (Eq. 18), Pa; 0 away from the surface.
    pub tau_b_pa: f32,
    /// Critical bed shear stress on the local slope (Eqs. 16-17, 22-24), Pa.
    pub tau_bcr_pa: f32,
}

/// The rheology pass of one run, with its constants worked out once: [`Rheology::add_pair`]
/// and [`Rheology::finish`] are the one statement of the pass, which the brute-force
/// [`rheology_pass`] and the CPU backend's cell-list loop both call.
#[derive(Clone, Debug)]
pub struct Rheology<'a> {
    params: &'a Params,
    model: &'a SedimentModel,
    kernel: Wendland,
    support2: f32,
    coincident2: f32,
    /// Downward gravity, m/s2.
    g: f32,
    alpha_dp: f32,
    kappa_dp: f32,
    /// Kernel mass below which a sediment particle is at the bed surface (Eq. 26).
    reference_mass: f32,
    /// Tait's stiffness of the sediment.
    b_sed: f32,
    /// `(C_s dp)^2` of water's eddy viscosity, m2 (0: none).
    sps_length2: f32,
    /// This pass's pick-up draws (none: no particle waiting for its pick-up is released).
    draws: Option<Draws>,
}

impl<'a> Rheology<'a> {
    pub fn new(params: &'a Params, model: &'a SedimentModel) -> Rheology<'a> {
        let h = params.h;
        let mat = &model.material;
        let sed = &params.phases[model.sediment_phase];
        Rheology {
            kernel: Wendland::new(h, params.dim),
            support2: 4.0 * h * h,
            coincident2: 1e-12 * h * h,
            g: -params.gravity[(params.dim - 1) as usize],
            alpha_dp: alpha(mat.phi_rad),
            kappa_dp: kappa_c(mat.phi_rad, mat.cohesion_pa),
            reference_mass: mat.surface_mass_fraction * sed.mass,
            b_sed: tait_b(params.c0, sed.rho0),
            sps_length2: match params.viscosity {
                Viscosity::Multiphase { sps_length2, .. } => sps_length2,
                _ => 0.0,
            },
            draws: None,
            params,
            model,
        }
    }

    /// Kernel mass below which a sediment particle with water in reach is at the bed's
    /// surface (Eq. 26), kg.
    pub fn reference_mass(&self) -> f32 {
        self.reference_mass
    }

    /// The pass with the pick-up draws `draws`.
    pub fn with_draws(self, draws: Option<Draws>) -> Rheology<'a> {
        Rheology { draws, ..self }
    }

    fn is_sediment(&self, pos: &[f32; 4]) -> bool {
        phase_index(pos) == self.model.sediment_phase
    }

    /// The sums particle `x_i`, `v_i` starts from: a sediment particle counts itself.
    pub fn start(&self, x_i: &[f32; 4], v_i: &[f32; 4]) -> RheologySums {
        let mut s = RheologySums::default();
        if self.is_sediment(x_i) {
            let mass = self.params.phases[self.model.sediment_phase].mass;
            let vol = mass / v_i[3];
            s.sediment_volume = vol;
            s.mixture_volume = vol;
            s.kernel_mass = mass * self.kernel.w(0.0) * vol;
        }
        s
    }

    /// The volume m / rho of particle `x`, `v` (a neighbour's weight in every sum).
    pub fn volume(&self, x: &[f32; 4], v: &[f32; 4]) -> f32 {
        self.params.phases[phase_index(x)].mass / v[3]
    }

    /// Particle `x`, `v` as its pairs see it.
    pub fn side(&self, x: &[f32; 4], v: &[f32; 4]) -> RheologySide {
        RheologySide {
            x: [x[0], x[1], x[2]],
            v: [v[0], v[1], v[2]],
            sediment: self.is_sediment(x),
        }
    }

    /// Adds neighbour j to particle i's sums: nothing beyond the support or for a coincident
    /// pair.
    pub fn add_pair(
        &self,
        i: (&[f32; 4], &[f32; 4]),
        j: (&[f32; 4], &[f32; 4]),
        s: &mut RheologySums,
    ) {
        let side = self.side(i.0, i.1);
        self.add_pair_of_volume(&side, j, self.volume(j.0, j.1), true, s);
    }

    /// [`Rheology::add_pair`] in the lanes `reach` of `i` (`true` for one particle), with
    /// the neighbour's volume `vol_j` ([`Rheology::volume`]) worked out beforehand, once per
    /// particle rather than once per pair.
    #[inline(always)]
    pub fn add_pair_of_volume<L: Real>(
        &self,
        i: &RheologySide<L>,
        j: (&[f32; 4], &[f32; 4]),
        vol_j: f32,
        reach: L::Mask,
        s: &mut RheologySums<L>,
    ) {
        // The dimension a constant: loops to a bound read at run time kept the lanes' sums in
        // memory, each select a masked store that the next pair's load waited on.
        if self.params.dim == 2 {
            self.add_pair_in::<L, 2>(i, j, vol_j, reach, s);
        } else {
            self.add_pair_in::<L, 3>(i, j, vol_j, reach, s);
        }
    }

    /// [`Rheology::add_pair_of_volume`] in `D` dimensions.
    #[inline(always)]
    fn add_pair_in<L: Real, const D: usize>(
        &self,
        i: &RheologySide<L>,
        (x_j, v_j): (&[f32; 4], &[f32; 4]),
        vol_j: f32,
        reach: L::Mask,
        s: &mut RheologySums<L>,
    ) {
        let c = L::splat;
        let x_ij: [L; 3] = std::array::from_fn(|k| i.x[k] - c(x_j[k]));
        let r2 = x_ij[0] * x_ij[0] + x_ij[1] * x_ij[1] + x_ij[2] * x_ij[2];
        let near = reach & !r2.ge(c(self.support2)) & !r2.lt(c(self.coincident2));
        if !near.any() {
            return;
        }
        let pj = phase_index(x_j);
        let m_j = self.params.phases[pj].mass;
        let r = r2.sqrt();
        let f = self.kernel.grad_factor(r);
        let du: [L; 3] = std::array::from_fn(|k| c(v_j[k]) - i.v[k]);
        // In 2-D the third row and column are zero: the loops stop at the dimension.
        for (row, d) in s.grad.iter_mut().zip(du).take(D) {
            for (g, x) in row.iter_mut().zip(x_ij).take(D) {
                *g = L::select(near, *g + c(vol_j) * d * x * f, *g);
            }
        }
        let model = self.model;
        let near = near & i.sediment;
        if !near.any() {
            return;
        }
        if pj == model.sediment_phase || !self.params.phases[pj].mobile {
            // The bed's normal points away from the solid under it: sediment and walls.
            for (n, x) in s.normal.iter_mut().zip(x_ij) {
                *n = L::select(near, *n - c(vol_j) * f * x, *n);
            }
            // Counted only where the count is read: this is the pass's hottest loop.
            if model.rests_beside_solid {
                let up = x_ij[D - 1];
                let beside = near & level_solid(up, r2, model.dp_m);
                s.level_solids = L::select(beside, s.level_solids + c(1.0), s.level_solids);
            }
        }
        if pj != model.sediment_phase && pj != model.water_phase {
            return;
        }
        s.mixture_volume = L::select(near, s.mixture_volume + c(vol_j), s.mixture_volume);
        if pj == model.sediment_phase {
            let volume = s.sediment_volume;
            s.sediment_volume = L::select(near, volume + c(vol_j), volume);
            let mass = s.kernel_mass + c(m_j) * self.kernel.w(r) * c(vol_j);
            s.kernel_mass = L::select(near, mass, s.kernel_mass);
        } else {
            let nearer = near & r.lt(s.water_r);
            s.water_r = L::select(nearer, r, s.water_r);
            let u_j = if model.water_speed {
                std::array::from_fn(|k| c(v_j[k]))
            } else {
                du
            };
            for (u, d) in s.water_u.iter_mut().zip(u_j) {
                *u = L::select(nearer, d, *u);
            }
        }
    }

    /// Particle i's rheology from its sums, `before` its region word after the previous pass
    /// (whether it was held, and what of it was picked up; see [`rheology_pass`]), `id` its
    /// id (its pick-up draw's), `exchange` the bed load it was passed in the last pass and the
    /// particle it passes its own to ([`Exchange`]; `(0.0, NO_TARGET)` with none).
    pub fn finish(
        &self,
        x_i: &[f32; 4],
        v_i: &[f32; 4],
        s: &RheologySums,
        (before, id): (u32, u32),
        (upstream, target): (f32, u32),
    ) -> ParticleRheology {
        let params = self.params;
        let phase_i = &params.phases[phase_index(x_i)];
        if !phase_i.mobile {
            return ParticleRheology::NONE;
        }
        let eps = strain_rate(&s.grad, params.dim);
        let ii_d = second_invariant(&eps);
        let (region, mu, held, (pickup, flux)) = if self.is_sediment(x_i) {
            self.classify(v_i[3], s, ii_d, (before, id, upstream))
        } else {
            let eddy = sps_viscosity(v_i[3], self.sps_length2, ii_d);
            (Region::Water as u32, phase_i.mu + eddy, false, (0, NO_FLUX))
        };
        let mut stress = [[0.0_f32; 3]; 3];
        // Shields-only holds carry no stress, as that mode always had; Drucker-Prager holds
        // keep theirs (`super::hold`).
        if !(held && self.model.shields_only) {
            for a in 0..3 {
                for b in 0..3 {
                    stress[a][b] = 2.0 * mu * eps[a][b];
                }
            }
        }
        ParticleRheology {
            stress,
            mu,
            region,
            held,
            pickup,
            flux,
            target: if flux == NO_FLUX { NO_TARGET } else { target },
        }
    }

    /// The Shields chain (Eqs. 16-26) of a sediment particle from its sums: whether it lies at
    /// the bed's surface, the nearest water particle's distance and speed, the
    /// friction velocity of the log law there, and the bed shear stress against its critical
    /// value on the local slope (infinite away from the surface, where Shields does not apply).
    pub fn shields_chain(&self, s: &RheologySums) -> ShieldsChain {
        let mat = &self.model.material;
        let at_surface = self.at_surface(s);
        let speed = norm3(s.water_u);
        let mut chain = ShieldsChain {
            at_surface,
            z_m: s.water_r,
            speed_m_per_s: speed,
            u_star_m_per_s: 0.0,
            tau_b_pa: 0.0,
            tau_bcr_pa: f32::INFINITY,
        };
        if at_surface {
            let u_star = friction_velocity(speed, s.water_r, mat.ks_m(), mat.nu_w).u_star;
            let theta = critical_shields(u_star * mat.d50_m / mat.nu_w);
            let tau_bcr0 =
                critical_bed_shear_stress(theta, mat.rho_s, mat.rho_w, self.g, mat.d50_m);
            let k = slope_factors(s.normal, s.water_u, self.params.dim, mat.phi_rad);
            chain.u_star_m_per_s = u_star;
            chain.tau_b_pa = bed_shear_stress(mat.rho_w, u_star);
            chain.tau_bcr_pa = sloped_critical_stress(tau_bcr0, k, 1.0);
        }
        chain
    }

    /// Region, apparent viscosity, hold, and mass picked up and bed load passed on, of a
    /// sediment particle of density `rho_i`, of region word `before` after the last pass, of id
    /// `id`, passed `upstream` from the held particle upstream.
    fn classify(
        &self,
        rho_i: f32,
        s: &RheologySums,
        ii_d: f32,
        (before, id, upstream): (u32, u32, f32),
    ) -> (u32, f32, bool, (i32, f32)) {
        let held_before = before & REGION_HELD != 0;
        let (model, mat) = (self.model, &self.model.material);
        let sed = &self.params.phases[model.sediment_phase];
        let p = pressure(rho_i, sed.rho0, self.b_sed);
        let tau_y = yield_stress(
            self.alpha_dp,
            self.kappa_dp,
            skeleton_pressure(p, mat.rho_s, mat.rho_w),
        );
        let ShieldsChain {
            at_surface,
            tau_b_pa: tau_b,
            tau_bcr_pa: tau_bcr,
            ..
        } = self.shields_chain(s);
        let c_v = volume_fraction(s.sediment_volume, s.mixture_volume);
        let stress = (tau_b, tau_bcr);
        let exner = model.exner();
        let units = word_units(before, exner);
        // Under Exner's balance a grain the bed did not hold carries what was worn off it, and
        // wears no more: what the flow carries off a moving grain is the grain. What was passed
        // to it settles on it.
        let (picked_up, pickup, flux) = if exner && !held_before {
            self.settle(units, id, upstream)
        } else {
            self.pick_up(units, id, stress, upstream)
        };
        // The stress the particle carries, which only the Drucker-Prager mode reads.
        let sqrt_j2 = if model.shields_only {
            0.0
        } else {
            let mu_y = hbp_viscosity(ii_d, tau_y, mat.hbp_m, mat.hbp_n, mat.mu_s_pa_s);
            2.0 * mu_y.min(model.mu_max) * ii_d.max(0.0).sqrt()
        };
        let region = sediment_region(&RegionInputs {
            shields_only: model.shields_only,
            held_before,
            at_surface,
            tau_b,
            tau_bcr,
            sqrt_j2,
            tau_y,
            c_v,
            picked_up,
            lone: model.rests_beside_solid && s.level_solids == 0.0,
        });
        let mu = apparent_viscosity(region, ii_d, tau_y, tau_bcr, c_v, mat);
        let held = region == Region::Unyielded;
        // What was worn off a particle stays with it while it is held, and only then; under
        // Exner's balance, where it went downstream as bed load, wherever the particle goes.
        let pickup = if exner || (held && held_before) {
            pickup
        } else {
            0
        };
        // A held particle at the bed's top passes on or keeps bed load even where no water
        // reaches it yet, so what the flow carries to a wet front settles there; under Exner's
        // balance one the bed lets go in this pass still passes on what it carries.
        let flux = if (held || (exner && held_before)) && self.at_bed_top(s) {
            flux
        } else {
            NO_FLUX
        };
        (region as u32, mu.min(model.mu_max), held, (pickup, flux))
    }
}

impl Rheology<'_> {
    /// The bed-load exchange of sediment particle `id` at `x_i` with its neighbours, when what
    /// is worn off it is net of what settles on it (`van_rijn_exner`), from its sums `s`, in a
    /// pass that wears the bed (one with draws; another would not read it). Every sediment
    /// particle is passed the loads named to it, wherever it now lies; one held (`before` its
    /// word) at the bed's surface under flowing water passes its own down that flow.
    pub fn exchange_of(
        &self,
        (x_i, id): (&[f32; 4], u32),
        s: &RheologySums,
        before: u32,
    ) -> Option<Exchange> {
        let wears = self.model.exner() && self.draws.is_some();
        (wears && self.is_sediment(x_i)).then(|| {
            let speed = norm3(s.water_u);
            let names = before & REGION_HELD != 0 && self.at_surface(s) && speed > 0.0;
            let along = names.then(|| std::array::from_fn(|k| s.water_u[k] / speed));
            Exchange::new(id, [x_i[0], x_i[1], x_i[2]], along, self.model.dp_m)
        })
    }

    /// Eq. 26: a water particle within the support and a kernel mass of sediment below the
    /// surface fraction of a particle's.
    fn at_surface(&self, s: &RheologySums) -> bool {
        s.water_r < f32::INFINITY && s.kernel_mass < self.reference_mass
    }

    /// Where bed load is passed on and settles: Eq. 26's surface, or, where no water reaches
    /// yet, as light a kernel mass under a normal within 45 deg of straight up (the top of a
    /// dry bed, not its underside or its end face).
    fn at_bed_top(&self, s: &RheologySums) -> bool {
        let n = s.normal;
        let up = n[(self.params.dim - 1) as usize];
        let faces_up = up > 0.0 && 2.0 * up * up > n[0] * n[0] + n[1] * n[1] + n[2] * n[2];
        self.at_surface(s) || (s.kernel_mass < self.reference_mass && faces_up)
    }
}

mod exchange;
mod oracle;
mod sums;
mod wear;

pub use exchange::{Exchange, NO_TARGET};
pub use oracle::{rheology_pass, rheology_pass_drawn, rheology_pass_exner};
pub use sums::{RheologySide, RheologySums};

#[cfg(test)]
mod tests;
