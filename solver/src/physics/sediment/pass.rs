//! The rheology pass of the water-sediment model, brute force over all pairs: for every particle
//! its strain rate, region and apparent viscosity, hence its viscous stress `tau = 2 mu eps`
//! (Eqs. 11-15, 26-33, Figure 2); then the stress divergence of the momentum equation (Eq. 10).
//! The GPU's `shaders/stages/rheology.wgsl` and the multiphase branch of `forces_wcsph.wgsl`
//! must give the same numbers (up to summation order).
//!
//! Choices the paper leaves open, each stated where it is made:
//! - the skeleton pressure of Drucker-Prager ([`skeleton_pressure`]);
//! - what the Shields-only mode does with a sediment particle that is neither eroded nor inside
//!   the bed ([`classify_shields_only`]);
//! - the cap on the apparent viscosity ([`SedimentModel::mu_max`]), and the hold of
//!   un-yielded sediment that makes up for it ([`super::hold`]);
//! - the bed slope, from the normal of the sediment-water interface ([`slope_factors`]).

use super::SedimentParams;
use super::drucker_prager::{alpha, kappa_c, yield_stress};
use super::rheology::{Tensor3, hbp_viscosity, second_invariant, strain_rate};
use super::shields::{
    bed_shear_stress, critical_bed_shear_stress, critical_shields, friction_velocity, k_beta,
    k_gamma, sloped_critical_stress,
};
use super::suspension::{
    Region, SUSPENSION_CONCENTRATION, apparent_viscosity, classify, volume_fraction,
};
use crate::physics::Params;
use crate::physics::eos::{pressure, tait_b};
use crate::physics::interaction::{PairGeometry, phase_index, wall_scale};
use crate::physics::kernel::Wendland;

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
    /// Largest apparent viscosity, Pa s, of the stress a particle carries. An explicit scheme
    /// is stable for `dt <= 0.125 h^2 rho / mu`; the un-yielded HBP viscosity (tau_y m, tens of
    /// thousands of Pa s for the Louvain bed) would need steps 10^2 to 10^3 times shorter than
    /// the acoustic ones.
    pub mu_max: f32,
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
}

/// Bit of a region word marking sediment held fixed; mirrors `REGION_HELD` of
/// `shaders/common/sediment.wgsl`.
pub const REGION_HELD: u32 = 256;

impl ParticleRheology {
    /// The region word the backends store per particle: the region, and `REGION_HELD`.
    pub fn word(&self) -> u32 {
        self.region | if self.held { REGION_HELD } else { 0 }
    }
}

/// Sums a particle gathers from its neighbours in the rheology pass.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RheologySums {
    /// `grad[a][b] = sum_j V_j (u_j - u_i)_a (grad_i W_ij)_b` (Eq. 13).
    grad: Tensor3,
    sediment_volume: f32,
    mixture_volume: f32,
    kernel_mass: f32,
    /// `sum_water V_j grad_i W_ij`: points from the sediment into the water.
    normal: [f32; 3],
    /// Distance to the nearest water particle and its velocity relative to this one.
    nearest_water: Option<(f32, [f32; 3])>,
}

/// Skeleton pressure p of Eq. 31, Pa, from the sediment particle's pressure `p` (its Tait
/// pressure, total: grains and pore water).
///
/// The paper calls it the skeleton pressure without saying how the pore water pressure is taken
/// out. Here the pore water carries the fraction `rho_w / rho_s` of the total:
/// `p_skel = p (1 - rho_w / rho_s)`. At depth d below a bed surface that is itself at the free
/// surface this is exactly the effective stress `(rho_s - rho_w) g d`; under a water column of
/// pressure p_top it adds `p_top (1 - rho_w / rho_s)`, making the bed stronger than it is. A
/// pore pressure carried from the water above would remove that bias at the cost of one more
/// per-particle state.
pub fn skeleton_pressure(p: f32, rho_s: f32, rho_w: f32) -> f32 {
    p * (1.0 - rho_w / rho_s)
}

/// `k_beta k_gamma` of Eqs. 22-24 from the bed's outward normal `n` (any length, pointing into
/// the water) and the flow velocity `u` over it, in `dim` dimensions (vertical axis `dim - 1`).
///
/// The slope is the normal's tilt: `tan(beta) = n_s / n_v` along the flow's horizontal direction
/// s, `tan(gamma) = |n_t| / n_v` across it (3-D only). The flow runs down the slope when the
/// normal leans the way the flow goes (`n_s > 0`). With no horizontal flow, or no normal, the
/// bed counts as flat (factor 1); a normal pointing down (an overhang) gives beta >= 90 degrees.
pub fn slope_factors(n: [f32; 3], u: [f32; 3], dim: u32, phi: f32) -> f32 {
    let v = (dim - 1) as usize;
    let horizontal = if dim == 2 { 1 } else { 2 };
    let speed_h: f32 = (0..horizontal).map(|k| u[k] * u[k]).sum::<f32>().sqrt();
    let n_len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    if speed_h == 0.0 || n_len == 0.0 {
        return 1.0;
    }
    let mut n_s = 0.0;
    for k in 0..horizontal {
        n_s += n[k] * u[k] / speed_h;
    }
    let n_t = if dim == 3 {
        (n[0] * u[1] - n[1] * u[0]) / speed_h
    } else {
        0.0
    };
    let beta = n_s.abs().atan2(n[v]);
    let gamma = n_t.abs().atan2(n[v]);
    k_beta(beta, phi, n_s > 0.0) * k_gamma(gamma, phi)
}

/// Region of a sediment particle in the Shields-only mode: bed load where Eq. 25 holds, then
/// suspended wherever `c_v < 0.3` (eroded or not: a grain that has left the bed is carried by
/// the water even when the flow next to it is below the Shields threshold), otherwise held.
pub fn classify_shields_only(at_surface: bool, tau_b: f32, tau_bcr: f32, c_v: f32) -> Region {
    if c_v < SUSPENSION_CONCENTRATION {
        Region::Suspended
    } else if at_surface && tau_b > tau_bcr {
        Region::BedLoad
    } else {
        Region::Unyielded
    }
}

fn sub3(a: &[f32; 4], b: &[f32; 4]) -> [f32; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn norm3(a: [f32; 3]) -> f32 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
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
            params,
            model,
        }
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

    /// Adds neighbour j to particle i's sums: nothing beyond the support or for a coincident
    /// pair.
    #[inline(always)]
    pub fn add_pair(
        &self,
        i: (&[f32; 4], &[f32; 4]),
        j: (&[f32; 4], &[f32; 4]),
        s: &mut RheologySums,
    ) {
        self.add_pair_of_volume(i, j, self.volume(j.0, j.1), s);
    }

    /// [`Rheology::add_pair`] with the neighbour's volume `vol_j` ([`Rheology::volume`])
    /// worked out beforehand, once per particle rather than once per pair.
    #[inline(always)]
    pub fn add_pair_of_volume(
        &self,
        (x_i, v_i): (&[f32; 4], &[f32; 4]),
        (x_j, v_j): (&[f32; 4], &[f32; 4]),
        vol_j: f32,
        s: &mut RheologySums,
    ) {
        let x_ij = sub3(x_i, x_j);
        let r2 = x_ij[0] * x_ij[0] + x_ij[1] * x_ij[1] + x_ij[2] * x_ij[2];
        if r2 >= self.support2 || r2 < self.coincident2 {
            return;
        }
        let pj = phase_index(x_j);
        let m_j = self.params.phases[pj].mass;
        let r = r2.sqrt();
        let f = self.kernel.grad_factor(r);
        let du = sub3(v_j, v_i);
        // In 2-D the third row and column are zero: the loops stop at the dimension.
        let dim = self.params.dim as usize;
        for (row, d) in s.grad.iter_mut().zip(du).take(dim) {
            for (g, x) in row.iter_mut().zip(x_ij).take(dim) {
                *g += vol_j * d * x * f;
            }
        }
        let model = self.model;
        if !self.is_sediment(x_i) || (pj != model.sediment_phase && pj != model.water_phase) {
            return;
        }
        s.mixture_volume += vol_j;
        if pj == model.sediment_phase {
            s.sediment_volume += vol_j;
            s.kernel_mass += m_j * self.kernel.w(r) * vol_j;
        } else {
            for (k, n) in s.normal.iter_mut().enumerate() {
                *n += vol_j * f * x_ij[k];
            }
            if s.nearest_water.is_none_or(|(rn, _)| r < rn) {
                s.nearest_water = Some((r, du));
            }
        }
    }

    /// Particle i's rheology from its sums, `held_before` whether it was held after the
    /// previous pass (see [`rheology_pass`]).
    pub fn finish(
        &self,
        x_i: &[f32; 4],
        v_i: &[f32; 4],
        s: &RheologySums,
        held_before: bool,
    ) -> ParticleRheology {
        let params = self.params;
        let phase_i = &params.phases[phase_index(x_i)];
        if !phase_i.mobile {
            return ParticleRheology {
                stress: [[0.0; 3]; 3],
                mu: 0.0,
                region: 0,
                held: false,
            };
        }
        let eps = strain_rate(&s.grad, params.dim);
        let ii_d = second_invariant(&eps);
        let (region, mu, held) = if self.is_sediment(x_i) {
            self.classify(v_i[3], s, ii_d, held_before)
        } else {
            (Region::Water as u32, phase_i.mu, false)
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
        }
    }

    /// Region, apparent viscosity and hold of a sediment particle of density `rho_i`.
    fn classify(
        &self,
        rho_i: f32,
        s: &RheologySums,
        ii_d: f32,
        held_before: bool,
    ) -> (u32, f32, bool) {
        let (model, mat) = (self.model, &self.model.material);
        let sed = &self.params.phases[model.sediment_phase];
        let p = pressure(rho_i, sed.rho0, self.b_sed);
        let tau_y = yield_stress(
            self.alpha_dp,
            self.kappa_dp,
            skeleton_pressure(p, mat.rho_s, mat.rho_w),
        );
        let at_surface = s.nearest_water.is_some() && s.kernel_mass < self.reference_mass;
        let (tau_b, tau_bcr) = match s.nearest_water {
            Some((z, u)) if at_surface => {
                let u_star = friction_velocity(norm3(u), z, mat.ks_m(), mat.nu_w).u_star;
                let theta = critical_shields(u_star * mat.d50_m / mat.nu_w);
                let tau_bcr0 =
                    critical_bed_shear_stress(theta, mat.rho_s, mat.rho_w, self.g, mat.d50_m);
                let k = slope_factors(s.normal, u, self.params.dim, mat.phi_rad);
                (
                    bed_shear_stress(mat.rho_w, u_star),
                    sloped_critical_stress(tau_bcr0, k, 1.0),
                )
            }
            _ => (0.0, f32::INFINITY),
        };
        let c_v = volume_fraction(s.sediment_volume, s.mixture_volume);
        let region = if model.shields_only {
            classify_shields_only(at_surface, tau_b, tau_bcr, c_v)
        } else if held_before && !(at_surface && tau_b > tau_bcr) {
            Region::Unyielded
        } else {
            let mu_y = hbp_viscosity(ii_d, tau_y, mat.hbp_m, mat.hbp_n, mat.mu_s_pa_s);
            let sqrt_j2 = 2.0 * mu_y.min(model.mu_max) * ii_d.max(0.0).sqrt();
            classify(true, at_surface, tau_b, tau_bcr, sqrt_j2, tau_y, c_v)
        };
        let mu = apparent_viscosity(region, ii_d, tau_y, tau_bcr, c_v, mat);
        (
            region as u32,
            mu.min(model.mu_max),
            region == Region::Unyielded,
        )
    }
}

/// The rheology of every particle (see the module doc), `held_before[i]` whether particle i was
/// held after the previous pass. In the Drucker-Prager mode a particle held before stays held
/// unless Shields makes it bed load: only [`super::hold::release_pass`], which follows this
/// pass, releases it by the stress of its neighbours.
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
    assert_eq!(pos.len(), vel_rho.len(), "positions and velocities differ");
    assert_eq!(pos.len(), held_before.len(), "positions and holds differ");
    let pass = Rheology::new(params, model);
    (0..pos.len())
        .map(|i| {
            let mut s = pass.start(&pos[i], &vel_rho[i]);
            for j in 0..pos.len() {
                pass.add_pair((&pos[i], &vel_rho[i]), (&pos[j], &vel_rho[j]), &mut s);
            }
            pass.finish(&pos[i], &vel_rho[i], &s, held_before[i])
        })
        .collect()
}

/// A particle as the stress divergence sees it: position, phase and `tau / rho^2`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StressSide {
    pub x: [f32; 3],
    pub phase: u32,
    pub tau_over_rho2: Tensor3,
}

/// The viscous part of the momentum equation (Eq. 10 with sigma = -p I + tau), pair by pair:
/// `sum_j m_j (tau_i / rho_i^2 + tau_j / rho_j^2) . grad_i W_ij`, m/s2, for a mobile particle
/// with the stresses of [`rheology_pass`]; a wall neighbour's mass is scaled by
/// [`wall_scale`] as in the pressure term (its stress is zero).
#[derive(Clone, Debug)]
pub struct StressDivergence<'a> {
    params: &'a Params,
    kernel: Wendland,
    support2: f32,
    coincident2: f32,
}

impl<'a> StressDivergence<'a> {
    pub fn new(params: &'a Params) -> StressDivergence<'a> {
        let h = params.h;
        StressDivergence {
            params,
            kernel: Wendland::new(h, params.dim),
            support2: 4.0 * h * h,
            coincident2: 1e-12 * h * h,
        }
    }

    pub fn side(&self, x: &[f32; 4], rho: f32, stress: &Tensor3) -> StressSide {
        let mut t = *stress;
        for row in &mut t {
            for v in row {
                *v /= rho * rho;
            }
        }
        StressSide {
            x: [x[0], x[1], x[2]],
            phase: phase_index(x) as u32,
            tau_over_rho2: t,
        }
    }

    /// Adds neighbour j's term to mobile particle i's acceleration `acc`.
    #[inline(always)]
    pub fn add_pair(&self, i: &StressSide, j: &StressSide, acc: &mut [f32; 3]) {
        let x_ij = [i.x[0] - j.x[0], i.x[1] - j.x[1], i.x[2] - j.x[2]];
        let r2 = x_ij[0] * x_ij[0] + x_ij[1] * x_ij[1] + x_ij[2] * x_ij[2];
        if r2 >= self.support2 || r2 < self.coincident2 {
            return;
        }
        let phases = &self.params.phases;
        let phase_j = &phases[j.phase as usize];
        let m_j = if phase_j.mobile {
            phase_j.mass
        } else {
            phase_j.mass * wall_scale(phases[i.phase as usize].rho0, phase_j.rho0)
        };
        let f = self.kernel.grad_factor(r2.sqrt());
        self.add_term(i, j, &PairGeometry { x_ij, f, m_j }, acc);
    }

    /// The term itself, on a pair whose geometry (`PairModel::add_pair`'s) is known.
    #[inline(always)]
    pub fn add_term(&self, i: &StressSide, j: &StressSide, g: &PairGeometry, acc: &mut [f32; 3]) {
        // In 2-D the third row and column are zero: the loops stop at the dimension.
        let dim = self.params.dim as usize;
        let rows = acc.iter_mut().zip(&i.tau_over_rho2).zip(&j.tau_over_rho2);
        for ((a, t_i), t_j) in rows.take(dim) {
            for ((ti, tj), x) in t_i.iter().zip(t_j).zip(g.x_ij).take(dim) {
                *a += g.m_j * (ti + tj) * x * g.f;
            }
        }
    }
}

/// [`StressDivergence`] for every particle by brute force (zero for walls).
pub fn stress_divergence(
    params: &Params,
    pos: &[[f32; 4]],
    vel_rho: &[[f32; 4]],
    rheology: &[ParticleRheology],
) -> Vec<[f32; 3]> {
    let div = StressDivergence::new(params);
    let sides: Vec<StressSide> = (0..pos.len())
        .map(|i| div.side(&pos[i], vel_rho[i][3], &rheology[i].stress))
        .collect();
    (0..pos.len())
        .map(|i| {
            let mut acc = [0.0_f32; 3];
            if params.phases[phase_index(&pos[i])].mobile {
                for j in &sides {
                    div.add_pair(&sides[i], j, &mut acc);
                }
            }
            acc
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    const DEG: f32 = std::f32::consts::PI / 180.0;

    #[test]
    fn flat_bed_has_unit_slope_factor() {
        // Normal straight up: beta = gamma = 0, Eqs. 22-23 give sin(phi)/sin(phi) = 1 and
        // cos(0) sqrt(1 - 0) = 1, whichever way the water flows.
        for u in [[0.3, 0.0, 0.0], [-0.3, 0.0, 0.0]] {
            assert_eq!(slope_factors([0.0, 1.0, 0.0], u, 2, 30.0 * DEG), 1.0);
        }
        assert_eq!(
            slope_factors([0.0, 0.0, 2.0], [0.1, 0.2, 0.0], 3, 30.0 * DEG),
            1.0
        );
    }

    #[test]
    fn slope_factor_by_hand() {
        // A 2-D bed sloping down towards +x at 10 deg: outward normal (sin 10, cos 10).
        // Flow towards +x runs down the slope: sin(30 - 10) / sin 30 = 0.342020 / 0.5 = 0.684040.
        // Flow towards -x runs up it: sin(40) / sin(30) = 0.642788 / 0.5 = 1.285575.
        let n = [(10.0 * DEG).sin(), (10.0 * DEG).cos(), 0.0];
        let down = slope_factors(n, [0.2, 0.0, 0.0], 2, 30.0 * DEG);
        let up = slope_factors(n, [-0.2, 0.0, 0.0], 2, 30.0 * DEG);
        assert!((down - 0.684_040).abs() < 1e-5, "{down}");
        assert!((up - 1.285_575).abs() < 1e-5, "{up}");
        // 3-D, the same tilt across a flow along y: gamma = 10 deg, beta = 0;
        // cos 10 sqrt(1 - tan^2 10 / tan^2 30) = 0.984808 sqrt(1 - 0.031091 / 0.333333)
        // = 0.984808 sqrt(0.906726) = 0.984808 * 0.952222 = 0.937755.
        let n3 = [(10.0 * DEG).sin(), 0.0, (10.0 * DEG).cos()];
        let across = slope_factors(n3, [0.0, 0.2, 0.0], 3, 30.0 * DEG);
        assert!((across - 0.937_755).abs() < 1e-5, "{across}");
    }

    #[test]
    fn skeleton_pressure_is_effective_stress_at_the_surface() {
        // 5 cm below a bed surface that is the free surface: p = rho_s g d = 2710 * 9.81 * 0.05
        // = 1329.255 Pa; effective stress (rho_s - rho_w) g d = 1710 * 9.81 * 0.05 = 838.755 Pa.
        let p = skeleton_pressure(1329.255, 2710.0, 1000.0);
        assert!((p - 838.755).abs() < 1e-2, "{p}");
    }

    #[test]
    fn shields_only_regions() {
        assert_eq!(classify_shields_only(true, 0.5, 0.2, 0.6), Region::BedLoad);
        assert_eq!(
            classify_shields_only(true, 0.1, 0.2, 0.6),
            Region::Unyielded
        );
        assert_eq!(
            classify_shields_only(false, 0.5, 0.2, 0.6),
            Region::Unyielded
        );
        assert_eq!(
            classify_shields_only(true, 0.1, 0.2, 0.1),
            Region::Suspended
        );
    }
}
