//! The force pass of weakly compressible SPH (Zubeldia et al. 2018, Eqs. 9-10), brute force over
//! all pairs:
//! - continuity, Eq. 9, with Molteni-Colagrossi (2009) density diffusion in the hydrostatic form
//!   of Fourtakas et al. (2019);
//! - momentum, Eq. 10 with sigma = -p I, plus Monaghan (1992) artificial viscosity in the
//!   DualSPHysics form or Morris et al. (1997) laminar viscosity;
//! - dynamic boundary (DBC) walls of Crespo et al. (2007): wall particles get a density rate from
//!   the fluid around them and nothing else.
//!
//! The GPU visits neighbours through a cell list; both must give the same sums (up to summation
//! order), so this file is the specification of what each pair contributes.

use super::eos::{pressure, tait_b};
use super::kernel::Wendland;
use super::{Params, Viscosity};

/// Result of one force pass, one entry per particle.
#[derive(Clone, Debug, PartialEq)]
pub struct Interaction {
    /// `[ax, ay, az, d rho/dt]`: acceleration in m/s2 including gravity (zero for walls), and the
    /// density rate in kg/(m3 s).
    pub forces: Vec<[f32; 4]>,
    /// Per-particle time-step limit in s before the CFL factor:
    /// `min(sqrt(h / |a_i|), h / (c0 + visc_max_i))`; `f32::INFINITY` for walls.
    pub dt_limit: Vec<f32>,
}

/// Factor by which a wall particle's mass and density are scaled as a fluid particle of rest
/// density `rho0_fluid` sees it, the walls being made of the first phase (`rho0_wall`).
///
/// A wall stands in for the fluid next to it: with its own mass and density, a wall of water
/// under a sand bed (rho0 ratio r = 2.71) would push the sand with `p / rho_wall^2`, r^2 times
/// the sand's own `p / rho_sand^2` at the same pressure, and drive a convection cell up the side
/// walls (measured: sand rose 2 cm along them in 2 s of still water). Scaled, the pair sees the
/// volume and the pressure the wall has, at the fluid's density. 1 for the walls' own phase, so
/// single-phase results are unchanged to the bit.
pub fn wall_scale(rho0_fluid: f32, rho0_wall: f32) -> f32 {
    rho0_fluid / rho0_wall
}

/// Phase index stored in the bits of a position's w.
pub(crate) fn phase_index(pos: &[f32; 4]) -> usize {
    pos[3].to_bits() as usize
}

fn dot3(a: [f32; 3], b: [f32; 3]) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// One particle as its pairs see it: position, velocity, density, the pressure of the momentum
/// equation over rho^2, its volume m / rho and its phase index. What depends on the particle
/// alone is worked out here, once, rather than in each of its some forty pairs.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Side {
    pub x: [f32; 3],
    pub v: [f32; 3],
    pub rho: f32,
    pub p_over_rho2: f32,
    pub vol: f32,
    pub phase: u32,
}

/// What a pair needs of a phase, in a table of fixed size (phase indices are masked into it).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct PhaseConsts {
    rho0: f32,
    mass: f32,
    mu: f32,
    mobile: bool,
    /// Tait's stiffness B.
    b: f32,
    /// `rho0 g / B`, 1/m: the argument of the hydrostatic density difference per metre of
    /// height.
    hydro: f32,
}

/// Slots of the phase table; a power of two, the GPU uniform's `MAX_PHASES`.
const PHASE_SLOTS: usize = 4;

/// A pair within the kernel's support: `x_i - x_j`, the kernel factor F of
/// `grad_i W_ij = x_ij F`, and the neighbour's mass as `i` sees it (a wall's scaled).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PairGeometry {
    pub x_ij: [f32; 3],
    pub f: f32,
    pub m_j: f32,
}

/// The running sums of one particle's pair terms.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PairSum {
    pub acc: [f32; 3],
    pub drho: f32,
    /// Largest `|h v_ij . x_ij / (r^2 + eta^2)|` over the pairs, m/s (the viscous step bound).
    pub visc_max: f32,
}

/// The pair formulas of one run, with what they derive from `Params` computed once. Both the
/// brute-force [`interact`] and the CPU backend's cell-list loops call [`PairModel::add_pair`]:
/// it is the one statement of what a pair contributes (the WGSL force stage mirrors it).
#[derive(Clone, Debug)]
pub struct PairModel<'a> {
    params: &'a Params,
    phases: [PhaseConsts; PHASE_SLOTS],
    kernel: Wendland,
    support2: f32,
    coincident2: f32,
    eta2: f32,
    /// delta h c0 of the diffusion term, m2/s.
    delta_h_c0: f32,
    vertical: usize,
}

impl<'a> PairModel<'a> {
    pub fn new(params: &'a Params) -> PairModel<'a> {
        let h = params.h;
        let vertical = (params.dim - 1) as usize;
        assert!(params.phases.len() <= PHASE_SLOTS, "more phases than slots");
        let mut phases = [PhaseConsts::default(); PHASE_SLOTS];
        for (slot, ph) in phases.iter_mut().zip(&params.phases) {
            *slot = PhaseConsts {
                rho0: ph.rho0,
                mass: ph.mass,
                mu: ph.mu,
                mobile: ph.mobile,
                b: tait_b(params.c0, ph.rho0),
                hydro: ph.rho0 * -params.gravity[vertical] / tait_b(params.c0, ph.rho0),
            };
        }
        PairModel {
            phases,
            kernel: Wendland::new(h, params.dim),
            support2: 4.0 * h * h,
            // Pairs closer than this are treated as coincident: x_ij carries no direction.
            coincident2: 1e-12 * h * h,
            eta2: 0.01 * h * h,
            delta_h_c0: params.delta * h * params.c0,
            vertical,
            params,
        }
    }

    pub fn params(&self) -> &Params {
        self.params
    }

    /// The pressure of the momentum equation: Tait's, without tension when the case says so.
    pub fn pressure(&self, rho: f32, phase: usize) -> f32 {
        let ph = self.phase(phase as u32);
        let p = pressure(rho, ph.rho0, ph.b);
        if self.params.clamp_negative_pressure {
            p.max(0.0)
        } else {
            p
        }
    }

    /// Particle `pos`, `vel_rho` as a pair sees it.
    pub fn side(&self, pos: &[f32; 4], vel_rho: &[f32; 4]) -> Side {
        let phase = phase_index(pos);
        let rho = vel_rho[3];
        Side {
            x: [pos[0], pos[1], pos[2]],
            v: [vel_rho[0], vel_rho[1], vel_rho[2]],
            rho,
            p_over_rho2: self.pressure(rho, phase) / (rho * rho),
            vol: self.phase(phase as u32).mass / rho,
            phase: phase as u32,
        }
    }

    fn phase(&self, k: u32) -> &PhaseConsts {
        &self.phases[k as usize % PHASE_SLOTS]
    }

    /// Adds what neighbour `j` contributes to particle `i`'s density rate and acceleration:
    /// nothing beyond the support 2h, for a coincident pair, or between two walls. Returns
    /// the pair's geometry when `i` is mobile and `j` within reach, for the terms of other
    /// models over the same pair (the stress divergence of the multiphase model).
    #[inline(always)]
    pub fn add_pair(&self, i: &Side, j: &Side, sum: &mut PairSum) -> Option<PairGeometry> {
        let x_ij = [i.x[0] - j.x[0], i.x[1] - j.x[1], i.x[2] - j.x[2]];
        let r2 = dot3(x_ij, x_ij);
        if r2 >= self.support2 || r2 < self.coincident2 {
            return None;
        }
        let params = self.params;
        let (phase_i, phase_j) = (self.phase(i.phase), self.phase(j.phase));
        // DBC as in DualSPHysics: a wall's density answers to the fluid only.
        if !phase_i.mobile && !phase_j.mobile {
            return None;
        }
        let h = params.h;
        let f = self.kernel.grad_factor(r2.sqrt());
        // A wall's pressure over rho^2 at the density it stands in for: p / (r rho)^2.
        let (m_j, rho_j, p_j) = if phase_i.mobile && !phase_j.mobile {
            let r = wall_scale(phase_i.rho0, phase_j.rho0);
            (phase_j.mass * r, j.rho * r, j.p_over_rho2 / (r * r))
        } else {
            (phase_j.mass, j.rho, j.p_over_rho2)
        };
        let v_ij = [i.v[0] - j.v[0], i.v[1] - j.v[1], i.v[2] - j.v[2]];
        let vdotr = dot3(v_ij, x_ij);
        // Continuity, Eq. 9: v_ij . grad_i W_ij = vdotr F.
        sum.drho += m_j * vdotr * f;
        if !phase_i.mobile {
            return None;
        }
        if params.delta > 0.0 && phase_j.mobile && j.phase == i.phase {
            // Same phase, not a wall: j's own mass and density, hence its own volume.
            sum.drho += self.delta_h_c0 * self.diffusion(i, j, r2, f) * j.vol;
        }
        // Pressure gradient, Eq. 10 with sigma = -p I.
        let mut coef = -m_j * (i.p_over_rho2 + p_j);
        let mu_ij = h * vdotr / (r2 + self.eta2);
        sum.visc_max = sum.visc_max.max(mu_ij.abs());
        match params.viscosity {
            Viscosity::Artificial { alpha } | Viscosity::Multiphase { alpha } => {
                // Only approaching pairs are damped.
                if vdotr < 0.0 {
                    let pi_ij = -alpha * params.c0 * mu_ij / (0.5 * (i.rho + rho_j));
                    coef -= m_j * pi_ij;
                }
                for (a, x) in sum.acc.iter_mut().zip(x_ij) {
                    *a += coef * f * x;
                }
            }
            Viscosity::Laminar => {
                // x_ij . grad_i W_ij = r2 F.
                let s =
                    m_j * (phase_i.mu + phase_j.mu) * (r2 * f) / (i.rho * rho_j * (r2 + self.eta2));
                for k in 0..3 {
                    sum.acc[k] += coef * f * x_ij[k] + s * v_ij[k];
                }
            }
        }
        Some(PairGeometry { x_ij, f, m_j })
    }

    /// The density diffusion term psi_ij (before delta h c0 V_j); the hydrostatic density
    /// difference rho_h is subtracted so that a fluid at rest under gravity is not diffused
    /// towards uniform density. rho_h = rho0 ((1 + x)^(1/7) - 1), x = rho0 g dz / B, by its
    /// series: x is below 1e-3 for neighbours (dz < 2h), where three terms are exact in f32.
    #[inline(always)]
    fn diffusion(&self, i: &Side, j: &Side, r2: f32, f: f32) -> f32 {
        let rho_h = if self.params.hydrostatic_diffusion {
            let phase = self.phase(i.phase);
            let rho0 = phase.rho0;
            let x = phase.hydro * (i.x[self.vertical] - j.x[self.vertical]);
            rho0 * x * (1.0 / 7.0 + x * (-3.0 / 49.0 + x * (13.0 / 343.0)))
        } else {
            0.0
        };
        2.0 * (j.rho - i.rho - rho_h) * (-r2 * f) / (r2 + self.eta2)
    }

    /// Particle `i`'s `[ax, ay, az, d rho/dt]` (gravity added; zero acceleration for a wall)
    /// and its stable step before the CFL factor, `min(sqrt(h / |a|), h / (c0 + visc_max))`
    /// (`f32::INFINITY` for a wall); without `force_bound` (an imposed velocity) the
    /// acceleration does not bound the step.
    pub fn finish(&self, i: &Side, sum: &PairSum, force_bound: bool) -> ([f32; 4], f32) {
        let params = self.params;
        if !self.phase(i.phase).mobile {
            return ([0.0, 0.0, 0.0, sum.drho], f32::INFINITY);
        }
        let mut acc = sum.acc;
        for (a, g) in acc.iter_mut().zip(params.gravity) {
            *a += g;
        }
        let a = dot3(acc, acc).sqrt();
        let h = params.h;
        let dt_force = if a > 0.0 && force_bound {
            (h / a).sqrt()
        } else {
            f32::INFINITY
        };
        let dt_sound = h / (params.c0 + sum.visc_max);
        ([acc[0], acc[1], acc[2], sum.drho], dt_force.min(dt_sound))
    }
}

/// One force pass over all pairs closer than 2h.
///
/// Panics if the slices differ in length or a phase index is outside `params.phases`; both are
/// bugs of the caller, not bad input data.
pub fn interact(params: &Params, pos: &[[f32; 4]], vel_rho: &[[f32; 4]]) -> Interaction {
    assert_eq!(
        pos.len(),
        vel_rho.len(),
        "positions and velocities differ in length"
    );
    let model = PairModel::new(params);
    let sides: Vec<Side> = pos
        .iter()
        .zip(vel_rho)
        .map(|(p, v)| model.side(p, v))
        .collect();
    let mut forces = Vec::with_capacity(pos.len());
    let mut dt_limit = Vec::with_capacity(pos.len());
    for (i, side_i) in sides.iter().enumerate() {
        let mut sum = PairSum::default();
        for (j, side_j) in sides.iter().enumerate() {
            if j != i {
                model.add_pair(side_i, side_j, &mut sum);
            }
        }
        let (f, dt) = model.finish(side_i, &sum, true);
        forces.push(f);
        dt_limit.push(dt);
    }
    Interaction { forces, dt_limit }
}

#[cfg(test)]
mod tests {
    use super::super::Phase;
    use super::super::kernel::{grad_factor, smoothing_length};
    use super::*;

    fn sub3(a: &[f32; 4], b: &[f32; 4]) -> [f32; 3] {
        [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
    }

    const WATER: usize = 0;
    const WALL: usize = 1;

    fn water(mass: f32) -> Phase {
        Phase {
            rho0: 1000.0,
            mass,
            mu: 1e-3,
            mobile: true,
        }
    }

    fn wall(mass: f32) -> Phase {
        Phase {
            rho0: 1000.0,
            mass,
            mu: 0.0,
            mobile: false,
        }
    }

    fn params_2d(h: f32, c0: f32, mass: f32) -> Params {
        Params {
            dim: 2,
            h,
            c0,
            gravity: [0.0, -9.81, 0.0],
            delta: 0.0,
            hydrostatic_diffusion: true,
            clamp_negative_pressure: false,
            viscosity: Viscosity::Artificial { alpha: 0.0 },
            cfl: 0.2,
            phases: vec![water(mass), wall(mass)],
        }
    }

    fn at(x: f32, y: f32, phase: usize) -> [f32; 4] {
        [x, y, 0.0, f32::from_bits(phase as u32)]
    }

    /// A 2-D block of `nx * ny` particles with spacing dp, cell-centred from the origin.
    fn block(nx: usize, ny: usize, dp: f32, phase: usize) -> Vec<[f32; 4]> {
        let mut pos = Vec::new();
        for iy in 0..ny {
            for ix in 0..nx {
                pos.push(at((ix as f32 + 0.5) * dp, (iy as f32 + 0.5) * dp, phase));
            }
        }
        pos
    }

    fn close(a: f32, b: f32, rel: f32) -> bool {
        (a - b).abs() <= rel * b.abs().max(a.abs())
    }

    #[test]
    fn two_particles_by_hand() {
        // h = 1, r = 1: q = 1, F = 7/(4 pi) * (-5) * (1/2)^3 = -0.348_151_2.
        // c0 = 10, rho0 = 1000: B = 100 000 / 7 = 14 285.714.
        // rho_i = 1010: p_i = B (1.01^7 - 1) = 1030.505; p_j = 0 at rho_j = 1000.
        // a_i,x = -m (p_i / rho_i^2) F x_ij = 1030.505 / 1010^2 * 0.348_151_2 = 3.517_03e-4.
        // v_i = (-0.1, 0), v_j = 0: vdotr = -0.1, d rho_i/dt = m vdotr F = 0.034_815_12.
        let mut params = params_2d(1.0, 10.0, 1.0);
        params.gravity = [0.0; 3];
        let pos = [at(1.0, 0.0, WATER), at(0.0, 0.0, WATER)];
        let vel_rho = [[-0.1, 0.0, 0.0, 1010.0], [0.0, 0.0, 0.0, 1000.0]];
        let out = interact(&params, &pos, &vel_rho);
        let [a_i, a_j] = [out.forces[0], out.forces[1]];
        assert!(close(a_i[0], 3.517_03e-4, 1e-5), "{a_i:?}");
        assert_eq!(a_i[1], 0.0);
        assert!(close(a_i[3], 0.034_815_12, 1e-6), "{a_i:?}");
        assert!(close(a_j[3], 0.034_815_12, 1e-6), "{a_j:?}");
        // Equal masses: equal and opposite momentum change.
        assert_eq!(a_i[0], -a_j[0]);
        // dt: sqrt(h / |a|) = 37.7 loses to h / (c0 + |h vdotr / (r2 + eta2)|) = 1 / (10 + 0.1/1.01).
        assert!(close(out.dt_limit[0], 1.0 / (10.0 + 0.1 / 1.01), 1e-6));
    }

    #[test]
    fn lonely_particle_falls() {
        let params = params_2d(0.02, 20.0, 0.4);
        let out = interact(&params, &[at(0.0, 0.0, WATER)], &[[0.0, 0.0, 0.0, 1000.0]]);
        assert_eq!(out.forces[0], [0.0, -9.81, 0.0, 0.0]);
        let expected = (0.02_f32 / 9.81).sqrt().min(0.02 / 20.0);
        assert_eq!(out.dt_limit[0], expected);
    }

    #[test]
    fn resting_lattice_has_no_forces() {
        let dp = 0.01;
        let h = smoothing_length(1.2, 2, f64::from(dp)) as f32;
        let mut params = params_2d(h, 20.0, 1000.0 * dp * dp);
        let pos = block(15, 15, dp, WATER);

        // At rho0 every pressure is exactly 0: only gravity remains, and nothing compresses.
        // (Density diffusion stays off here: under gravity it rightly drives a uniform density
        // towards the hydrostatic profile.)
        let vel_rho = vec![[0.0, 0.0, 0.0, 1000.0]; pos.len()];
        let out = interact(&params, &pos, &vel_rho);
        for f in &out.forces {
            assert_eq!(*f, [0.0, -9.81, 0.0, 0.0]);
        }
        params.delta = 0.1;

        // Uniformly compressed: a particle with a full, symmetric neighbourhood feels no net
        // pressure force. Compare with the size of one neighbour's push.
        params.gravity = [0.0; 3];
        let vel_rho = vec![[0.0, 0.0, 0.0, 1010.0]; pos.len()];
        let out = interact(&params, &pos, &vel_rho);
        let b = tait_b(20.0, 1000.0);
        let p = pressure(1010.0, 1000.0, b);
        let one_pair =
            params.phases[0].mass * 2.0 * p / (1010.0 * 1010.0) * grad_factor(dp, h, 2).abs() * dp;
        let centre = 7 * 15 + 7;
        let a = out.forces[centre];
        assert!(
            a[0].abs() < 1e-4 * one_pair && a[1].abs() < 1e-4 * one_pair,
            "{a:?} vs {one_pair}"
        );
        assert_eq!(a[3], 0.0);
        // Near the free edge the unbalanced pressure pushes outwards (-x at the left column).
        assert!(out.forces[7 * 15][0] < 0.0);
    }

    /// Hydrostatic density `rho0 (1 + rho0 g (H - z) / B)^(1/7)`.
    fn hydrostatic(z: f32, surface: f32, params: &Params) -> f32 {
        let rho0 = 1000.0_f64;
        let b = f64::from(tait_b(params.c0, 1000.0));
        let depth = f64::from(surface) - f64::from(z);
        (rho0 * (1.0 + rho0 * 9.81 * depth / b).powf(1.0 / 7.0)) as f32
    }

    /// Molteni-Colagrossi term of particle 1 on particle 0 without the hydrostatic correction.
    fn plain_diffusion(params: &Params, pos: &[[f32; 4]; 2], vel_rho: &[[f32; 4]; 2]) -> f32 {
        let (h, rho_i, rho_j) = (params.h, vel_rho[0][3], vel_rho[1][3]);
        let x_ij = sub3(&pos[0], &pos[1]);
        let r2 = dot3(x_ij, x_ij);
        let f = grad_factor(r2.sqrt(), h, params.dim);
        params.delta * h * params.c0 * 2.0 * (rho_j - rho_i) * (-r2 * f) / (r2 + 0.01 * h * h)
            * (params.phases[0].mass / rho_j)
    }

    #[test]
    fn hydrostatic_pair_is_not_diffused() {
        let surface = 0.5_f32;
        let dp = 0.01_f32;
        let h = smoothing_length(1.2, 2, f64::from(dp)) as f32;
        let c0 = c0_dualsphysics(surface);
        let mut params = params_2d(h, c0, 1000.0 * dp * dp);
        params.delta = 0.1;
        let b = f64::from(tait_b(c0, 1000.0));

        // i at height z_i, j one kernel radius-ish below and beside it.
        for z_i in [surface, 0.4, 0.25, 0.1, 2.0 * h] {
            let pos = [
                at(0.2, z_i, WATER),
                at(0.2 + 0.5 * dp, z_i - 1.5 * dp, WATER),
            ];
            let rho = [
                hydrostatic(pos[0][1], surface, &params),
                hydrostatic(pos[1][1], surface, &params),
            ];
            let vel_rho = [[0.0, 0.0, 0.0, rho[0]], [0.0, 0.0, 0.0, rho[1]]];
            // At rest the continuity term vanishes: drho is the diffusion term alone.
            let drho = interact(&params, &pos, &vel_rho).forces[0][3];

            let plain = plain_diffusion(&params, &pos, &vel_rho);
            // The correction takes i as the top of a water column (p_i = 0), so it is exact at
            // the surface and leaves a second-order residue below it:
            // (rho_j - rho_i - rho_h) / (rho_j - rho_i) ~ -(6/7) rho0 g (H - z_i) / B.
            let depth_term = 1000.0 * 9.81 * f64::from(surface - z_i) / b;
            let allowed = 1.2 * 6.0 / 7.0 * depth_term + 2e-3;
            let ratio = f64::from(drho / plain).abs();
            assert!(
                ratio <= allowed,
                "z_i {z_i}: corrected/plain = {ratio}, allowed {allowed}"
            );
        }
    }

    /// DualSPHysics' default c0 = 10 sqrt(g H) for a still-water height H.
    fn c0_dualsphysics(height: f32) -> f32 {
        super::super::eos::c0_from_coefsound(10.0, 9.81, f64::from(height)) as f32
    }

    #[test]
    fn laminar_viscosity_slows_the_fast_layer() {
        let dp = 0.01;
        let (nx, ny) = (15, 9);
        let h = smoothing_length(1.2, 2, f64::from(dp)) as f32;
        let mut params = params_2d(h, 20.0, 1000.0 * dp * dp);
        params.gravity = [0.0; 3];
        params.viscosity = Viscosity::Laminar;
        let pos = block(nx, ny, dp, WATER);
        // Linear shear u = gamma y, at rest density.
        let vel_rho: Vec<[f32; 4]> = pos
            .iter()
            .map(|p| [50.0 * p[1], 0.0, 0.0, 1000.0])
            .collect();
        let out = interact(&params, &pos, &vel_rho);

        let top = (ny - 1) * nx + nx / 2;
        let bottom = nx / 2;
        let middle = (ny / 2) * nx + nx / 2;
        assert!(out.forces[top][0] < 0.0, "fastest layer must slow down");
        assert!(
            out.forces[bottom][0] > 0.0,
            "slowest layer must be dragged along"
        );
        // Inside, a linear profile has no Laplacian.
        assert!(out.forces[middle][0].abs() < 1e-4 * out.forces[top][0].abs());
        // Equal masses and pairwise antisymmetric terms: momentum is conserved.
        let total: f32 = out.forces.iter().map(|f| f[0]).sum();
        let scale: f32 = out.forces.iter().map(|f| f[0].abs()).sum();
        assert!(total.abs() < 1e-5 * scale, "{total} vs {scale}");
    }

    #[test]
    fn artificial_viscosity_damps_approach_only() {
        let mut params = params_2d(1.0, 10.0, 1.0);
        params.gravity = [0.0; 3];
        params.viscosity = Viscosity::Artificial { alpha: 0.1 };
        let pos = [at(1.0, 0.0, WATER), at(0.0, 0.0, WATER)];
        let approach = [[-0.1, 0.0, 0.0, 1000.0], [0.0, 0.0, 0.0, 1000.0]];
        let out = interact(&params, &pos, &approach);
        // By hand: mu = -0.1 / 1.01, pi = 0.1 * 10 * 0.1 / 1.01 / 1000, a = -pi F.
        let expected = 0.1 * 10.0 * (0.1 / 1.01) / 1000.0 * 0.348_151_2;
        assert!(
            close(out.forces[0][0], expected, 1e-5),
            "{:?}",
            out.forces[0]
        );
        assert_eq!(out.forces[0][0], -out.forces[1][0]);
        let recede = [[0.1, 0.0, 0.0, 1000.0], [0.0, 0.0, 0.0, 1000.0]];
        let out = interact(&params, &pos, &recede);
        assert_eq!(out.forces[0][0], 0.0);
    }

    #[test]
    fn walls_only_feel_fluid_density_rate() {
        let mut params = params_2d(1.0, 10.0, 1.0);
        params.delta = 0.1;
        let pos = [at(0.0, 0.0, WALL), at(1.0, 0.0, WALL), at(0.5, 1.0, WATER)];
        // Wall densities differ and walls "move" (velocity field set) to show that wall-wall pairs
        // contribute nothing.
        let vel_rho = [
            [0.3, 0.0, 0.0, 1005.0],
            [0.0, 0.0, 0.0, 1000.0],
            [0.0, -0.2, 0.0, 1000.0],
        ];
        let out = interact(&params, &pos, &vel_rho);
        for i in 0..2 {
            assert_eq!(out.forces[i][..3], [0.0; 3]);
            assert_eq!(out.dt_limit[i], f32::INFINITY);
            let x_ij = sub3(&pos[i], &pos[2]);
            let v_ij = sub3(&vel_rho[i], &vel_rho[2]);
            let r = dot3(x_ij, x_ij).sqrt();
            let expected = params.phases[0].mass * dot3(v_ij, x_ij) * grad_factor(r, 1.0, 2);
            assert_eq!(out.forces[i][3], expected);
        }
        // The fluid above the compressed wall is pushed up, and diffusion ignores the walls.
        assert!(out.forces[2][1] > -9.81);
        assert!(out.dt_limit[2].is_finite());
    }

    #[test]
    fn three_d_uses_z_as_vertical() {
        let dp = 0.02_f32;
        let h = smoothing_length(1.2, 3, f64::from(dp)) as f32;
        let mut params = params_2d(h, 20.0, 1000.0 * dp * dp * dp);
        params.dim = 3;
        params.gravity = [0.0, 0.0, -9.81];
        params.delta = 0.1;
        let surface = 0.3;
        let z = [surface, surface - dp];
        let rho = z.map(|zz| hydrostatic(zz, surface, &params));
        let phase = f32::from_bits(WATER as u32);
        let pos = [[0.1, 0.1, z[0], phase], [0.1, 0.1, z[1], phase]];
        let vel_rho = [[0.0, 0.0, 0.0, rho[0]], [0.0, 0.0, 0.0, rho[1]]];
        let out = interact(&params, &pos, &vel_rho);
        // i at the surface of a hydrostatic column: the correction cancels the diffusion up to
        // f32 rounding, as in the 2-D test.
        let plain = plain_diffusion(&params, &pos, &vel_rho);
        assert!(plain > 0.0);
        assert!(
            out.forces[0][3].abs() < 2e-3 * plain,
            "{} vs {plain}",
            out.forces[0][3]
        );
        // Pressure acts along z only.
        assert_eq!(out.forces[0][..2], [0.0, 0.0]);
    }
}
