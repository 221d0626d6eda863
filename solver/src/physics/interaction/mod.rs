//! The force pass of weakly compressible SPH (Zubeldia et al. 2018, Eqs. 9-10), brute force over
//! all pairs:
//! - continuity, Eq. 9, with Molteni-Colagrossi (2009) density diffusion in the hydrostatic form
//!   of Fourtakas et al. (2019);
//! - momentum, Eq. 10 with sigma = -p I, plus Monaghan (1992) artificial viscosity in the
//!   DualSPHysics form or Morris et al. (1997) laminar viscosity;
//! - dynamic boundary (DBC) walls of Crespo et al. (2007): wall particles get a density rate from
//!   the fluid around them and nothing else; or, under the generalised wall condition of Adami
//!   et al. (2012, `physics::boundary`), the density of the fluid's pressure around them.
//!
//! The GPU visits neighbours through a cell list; both must give the same sums (up to summation
//! order), so this file is the specification of what each pair contributes.

use super::boundary::{WallSums, density};
use super::eos::{pressure, tait_b};
use super::kernel::Wendland;
use super::lanes::{Lanes, Mask, Real, pack};
use super::timestep::stable_step;
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
#[inline(always)]
pub fn wall_scale<L: Real>(rho0_fluid: L, rho0_wall: L) -> L {
    rho0_fluid / rho0_wall
}

/// Phase index stored in the bits of a position's w.
pub(crate) fn phase_index(pos: &[f32; 4]) -> usize {
    pos[3].to_bits() as usize
}

#[inline(always)]
fn dot3<L: Real>(a: [L; 3], b: [L; 3]) -> L {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// One particle as its pairs see it (or [`LANES`](super::lanes::LANES) of them): position,
/// velocity, density, the pressure of the momentum equation over rho^2, its volume m / rho,
/// its phase and what a pair needs of that phase. What depends on the particle alone is worked
/// out here, once, rather than in each of its some forty pairs.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Side<L: Real = f32> {
    pub x: [L; 3],
    pub v: [L; 3],
    pub rho: L,
    pub p_over_rho2: L,
    pub vol: L,
    pub phase: L::Index,
    pub mobile: L::Mask,
    pub rho0: L,
    pub mass: L,
    pub mu: L,
    /// `rho0 g / B` of the phase, 1/m (see `PhaseConsts::hydro`).
    pub hydro: L,
    /// Moved at an imposed velocity (an inlet buffer): its density is not the flow's, and a
    /// wall under the generalised condition does not count it (`physics::boundary`).
    pub imposed: bool,
    /// Held fixed where it stands (the Shields-only mode's held sediment where it is not a
    /// wall, as under DBC): its acceleration is never used, so only its density rate is
    /// summed, and it does not bound the step, as the paper fixes it ("explicitly setting the
    /// velocity and acceleration to zero"). A Drucker-Prager hold may be released after the
    /// rheology pass, and is summed in full.
    pub fixed: L::Mask,
}

impl Side<Lanes> {
    /// Particles `sides` side by side ([`pack`]).
    #[inline(always)]
    pub fn lanes(sides: &[Side]) -> Side<Lanes> {
        pack(sides, |out: &mut Side<Lanes>, k, s| {
            for a in 0..3 {
                out.x[a].0[k] = s.x[a];
                out.v[a].0[k] = s.v[a];
            }
            out.rho.0[k] = s.rho;
            out.p_over_rho2.0[k] = s.p_over_rho2;
            out.vol.0[k] = s.vol;
            out.phase[k] = s.phase;
            out.mobile.0[k] = if s.mobile { u32::MAX } else { 0 };
            out.rho0.0[k] = s.rho0;
            out.mass.0[k] = s.mass;
            out.mu.0[k] = s.mu;
            out.hydro.0[k] = s.hydro;
            out.fixed.0[k] = if s.fixed { u32::MAX } else { 0 };
        })
    }
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
    /// `r0^2 = (CONTACT_REACH dp)^2` of the contact force a wall of this phase exerts under the
    /// generalised condition ([`PairModel::add_pair`]), m2; dp from the phase's particle volume.
    contact2: f32,
}

/// Reach r0 of the held bed's contact force, in dp (`PairModel::add_contact`). Water passing
/// between two neighbours of the bed's lattice comes within dp / 2 of both, so r0 must exceed
/// dp / 2; the barrier it then raises between the two, `2 D [q^12 / 12 - q^4 / 4 + 1 / 6]` per
/// unit mass with `q = 2 r0 / dp` and `D = u_max^2`, must stop water arriving at the fastest
/// speed the case allows, `u_max = c0 / 10`, pushed down by a dp of its own weight: `u_max^2 /
/// 2 + g dp`, 0.6 D at dp = 1 cm. That needs q >= 1.18; 0.6 dp (q = 1.2) gives 0.78 D. Every
/// dp further reaches the water resting on the bed: at dp / sqrt(2) (the lattice's gaps, as
/// first chosen) the water's first layer rode on it, 36 of the CI flume's water particles at
/// 0.70-0.80 dp from held sand and none nearer, and the flat sand bed's levels stood 6 mm
/// higher at P1 than without the force (README, levels section).
pub const CONTACT_REACH: f32 = 0.6;

/// Slots of the phase table; a power of two, the GPU uniform's `MAX_PHASES`.
const PHASE_SLOTS: usize = 4;

/// A pair within the kernel's support: `x_i - x_j`, the kernel factor F of
/// `grad_i W_ij = x_ij F`, and the neighbour's mass as `i` sees it (a wall's scaled), in the
/// lanes `valid` (particle `i` mobile and the pair within reach).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PairGeometry<L: Real = f32> {
    pub x_ij: [L; 3],
    pub f: L,
    pub m_j: L,
    pub valid: L::Mask,
}

/// The running sums of one particle's pair terms.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PairSum<L: Real = f32> {
    pub acc: [L; 3],
    pub drho: L,
    /// Largest `|h v_ij . x_ij / (r^2 + eta^2)|` over the pairs, m/s (the viscous step bound).
    pub visc_max: L,
}

impl PairSum<Lanes> {
    /// The sums of lane `k`.
    #[inline(always)]
    pub fn lane(&self, k: usize) -> PairSum {
        PairSum {
            acc: self.acc.map(|a| a.0[k]),
            drho: self.drho.0[k],
            visc_max: self.visc_max.0[k],
        }
    }
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
    /// D of the walls' contact force, m2/s2: the square of the flow's largest speed, c0 / 10
    /// (Eq. 5); 0 without the generalised wall condition.
    contact_d: f32,
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
                contact2: CONTACT_REACH
                    * CONTACT_REACH
                    * (ph.mass / ph.rho0).powf(2.0 / params.dim as f32),
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
            contact_d: if params.generalised_walls {
                0.01 * params.c0 * params.c0
            } else {
                0.0
            },
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
        let ph = self.phase(phase as u32);
        Side {
            x: [pos[0], pos[1], pos[2]],
            v: [vel_rho[0], vel_rho[1], vel_rho[2]],
            rho,
            p_over_rho2: self.pressure(rho, phase) / (rho * rho),
            vol: ph.mass / rho,
            phase: phase as u32,
            mobile: ph.mobile,
            rho0: ph.rho0,
            mass: ph.mass,
            mu: ph.mu,
            hydro: ph.hydro,
            imposed: false,
            fixed: false,
        }
    }

    fn phase(&self, k: u32) -> &PhaseConsts {
        &self.phases[k as usize % PHASE_SLOTS]
    }

    /// Adds what neighbour `j` contributes to particle `i`'s density rate and acceleration, in
    /// the lanes `reach` of `i` (`true` for one particle): nothing beyond the support 2h, for
    /// a coincident pair, or between two walls. Returns the pair's geometry when `i` is
    /// mobile and `j` within reach in some lane, for the terms of other models over the same
    /// pair (the stress divergence of the multiphase model).
    #[inline(always)]
    pub fn add_pair<L: Real>(
        &self,
        i: &Side<L>,
        j: &Side,
        reach: L::Mask,
        sum: &mut PairSum<L>,
    ) -> Option<PairGeometry<L>> {
        let s = L::splat;
        let x_ij = [i.x[0] - s(j.x[0]), i.x[1] - s(j.x[1]), i.x[2] - s(j.x[2])];
        let r2 = dot3(x_ij, x_ij);
        let mut near = reach & !r2.ge(s(self.support2)) & !r2.lt(s(self.coincident2));
        // DBC as in DualSPHysics: a wall's density answers to the fluid only.
        if !j.mobile {
            near = near & i.mobile;
        }
        if !near.any() {
            return None;
        }
        let params = self.params;
        let f = self.kernel.grad_factor(r2.sqrt());
        // A wall's pressure over rho^2 at the density it stands in for: p / (r rho)^2. (Two
        // walls are out by now: a wall j has a mobile i.)
        let (m_j, rho_j, p_j) = if j.mobile {
            (s(j.mass), s(j.rho), s(j.p_over_rho2))
        } else {
            let r = wall_scale(i.rho0, s(j.rho0));
            (s(j.mass) * r, s(j.rho) * r, s(j.p_over_rho2) / (r * r))
        };
        let v_ij = [i.v[0] - s(j.v[0]), i.v[1] - s(j.v[1]), i.v[2] - s(j.v[2])];
        let vdotr = dot3(v_ij, x_ij);
        // Continuity, Eq. 9: v_ij . grad_i W_ij = vdotr F.
        sum.drho = L::select(near, sum.drho + m_j * vdotr * f, sum.drho);
        let near = near & i.mobile;
        if !near.any() {
            return None;
        }
        if params.delta > 0.0 && j.mobile {
            // Same phase, not a wall: j's own mass and density, hence its own volume.
            let same = near & L::index_eq(i.phase, j.phase);
            let term = s(self.delta_h_c0) * self.diffusion(i, j, r2, f) * s(j.vol);
            sum.drho = L::select(same, sum.drho + term, sum.drho);
        }
        // A fixed particle's acceleration is never read: the rest is for the others.
        let near = near & !i.fixed;
        if !near.any() {
            return None;
        }
        if !j.mobile && self.contact_d > 0.0 && self.phase(j.phase).mobile {
            let other = near & !L::index_eq(i.phase, j.phase);
            self.add_contact(j, x_ij, r2, other, sum);
        }
        let pair = PairGeometry {
            x_ij,
            f,
            m_j,
            valid: near,
        };
        self.add_momentum(i, j, (rho_j, p_j), (&pair, r2, v_ij, vdotr), sum);
        Some(pair)
    }

    /// The pressure gradient (Eq. 10 with sigma = -p I) and the viscous term of pair `i`, `j`
    /// in the lanes `pair.valid`, given j's density and p / rho^2 as `i` sees them.
    #[inline(always)]
    fn add_momentum<L: Real>(
        &self,
        i: &Side<L>,
        j: &Side,
        (rho_j, p_j): (L, L),
        (pair, r2, v_ij, vdotr): (&PairGeometry<L>, L, [L; 3], L),
        sum: &mut PairSum<L>,
    ) {
        let s = L::splat;
        let params = self.params;
        let (near, m_j, f, x_ij) = (pair.valid, pair.m_j, pair.f, pair.x_ij);
        let mut coef = -m_j * (i.p_over_rho2 + p_j);
        let mu_ij = s(params.h) * vdotr / (r2 + s(self.eta2));
        sum.visc_max = L::select(near, sum.visc_max.max(mu_ij.abs()), sum.visc_max);
        match params.viscosity {
            Viscosity::Artificial { alpha } | Viscosity::Multiphase { alpha, .. } => {
                // Only approaching pairs are damped.
                let pi_ij = s(-alpha * params.c0) * mu_ij / (s(0.5) * (i.rho + rho_j));
                coef = L::select(vdotr.lt(s(0.0)), coef - m_j * pi_ij, coef);
                for (a, x) in sum.acc.iter_mut().zip(x_ij) {
                    *a = L::select(near, *a + coef * f * x, *a);
                }
            }
            Viscosity::Laminar => {
                // x_ij . grad_i W_ij = r2 F.
                let visc =
                    m_j * (i.mu + s(j.mu)) * (r2 * f) / (i.rho * rho_j * (r2 + s(self.eta2)));
                for k in 0..3 {
                    let a = sum.acc[k];
                    sum.acc[k] = L::select(near, a + (coef * f * x_ij[k] + visc * v_ij[k]), a);
                }
            }
        }
    }

    /// The contact force of held-bed particle `j` (a particle of a mobile phase standing as a
    /// wall) on a particle of another phase closer than `r0` ([`CONTACT_REACH`] dp), under the
    /// generalised wall condition: Monaghan's (1994) boundary force, `D ((r0 / r)^12 - (r0 /
    /// r)^4) x_ij / r^2` per unit mass. A wall under that condition takes the pressure of the
    /// fluid around it, so water that got between two rows of the held bed (through a hole a
    /// pick-up left) feels its own pressure all round and travels through the bed to the floor
    /// and out (`physics::boundary`). Water on the bed mostly stands farther off than r0, and
    /// one in a gap of the lattice stands `dp / sqrt(2)` from four of them: the force acts on
    /// water squeezing between two, and lightly on the few pressed onto the bed (5 of the CI
    /// flume's water particles at 0.5-0.6 dp at 30 s). Not on the bed's own sand sliding over it, nor from the
    /// walls (both tried: the sand was shot off the bed by it at the jet's impact, and the
    /// inlet's corner blew up).
    #[inline(always)]
    fn add_contact<L: Real>(
        &self,
        j: &Side,
        x_ij: [L; 3],
        r2: L,
        near: L::Mask,
        sum: &mut PairSum<L>,
    ) {
        let s = L::splat;
        let r0_2 = s(self.phase(j.phase).contact2);
        let close = near & r2.lt(r0_2);
        if !close.any() {
            return;
        }
        let q2 = r0_2 / r2;
        let q4 = q2 * q2;
        let coef = s(self.contact_d) * (q4 * q4 * q4 - q4) / r2;
        for (a, x) in sum.acc.iter_mut().zip(x_ij) {
            *a = L::select(close, *a + coef * x, *a);
        }
    }

    /// Adds fluid neighbour `j` to the sums of wall `i` under the generalised wall condition
    /// (`physics::boundary`), in the lanes `reach` of `i` (`true` for one wall): nothing for
    /// another wall, an imposed-velocity particle, or one beyond the support. Apart from
    /// [`PairModel::add_pair`]: only walls need it, and its accumulators in the pair loop's
    /// lanes cost every particle a third of its speed.
    #[inline(always)]
    pub fn add_wall_pair<L: Real>(
        &self,
        i: &Side<L>,
        j: &Side,
        reach: L::Mask,
        sums: &mut WallSums<L>,
    ) {
        // Most of a wall's neighbours are walls: they are out before any arithmetic, for all
        // the lanes at once.
        if !j.mobile || j.imposed {
            return;
        }
        let s = L::splat;
        let x_ij = [i.x[0] - s(j.x[0]), i.x[1] - s(j.x[1]), i.x[2] - s(j.x[2])];
        let r2 = dot3(x_ij, x_ij);
        let near = reach & !r2.ge(s(self.support2)) & !r2.lt(s(self.coincident2));
        if !near.any() {
            return;
        }
        let p_j = j.p_over_rho2 * j.rho * j.rho;
        sums.add(near, self.kernel.w(r2.sqrt()), s(p_j), s(j.rho), x_ij);
    }

    /// Wall `i`'s density under the generalised wall condition, from its sums: that of the
    /// fluid's pressure around it, rest density when dry.
    pub fn wall_density(&self, i: &Side, sums: &WallSums) -> f32 {
        let ph = self.phase(i.phase);
        sums.pressure(self.params.gravity)
            .map_or(ph.rho0, |p| density(p, ph.rho0, ph.b))
    }

    /// The density diffusion term psi_ij (before delta h c0 V_j); the hydrostatic density
    /// difference rho_h is subtracted so that a fluid at rest under gravity is not diffused
    /// towards uniform density. rho_h = rho0 ((1 + x)^(1/7) - 1), x = rho0 g dz / B, by its
    /// series: x is below 1e-3 for neighbours (dz < 2h), where three terms are exact in f32.
    #[inline(always)]
    fn diffusion<L: Real>(&self, i: &Side<L>, j: &Side, r2: L, f: L) -> L {
        let s = L::splat;
        let rho_h = if self.params.hydrostatic_diffusion {
            let x = i.hydro * (i.x[self.vertical] - s(j.x[self.vertical]));
            i.rho0 * x * (s(1.0 / 7.0) + x * (s(-3.0 / 49.0) + x * s(13.0 / 343.0)))
        } else {
            s(0.0)
        };
        s(2.0) * (s(j.rho) - i.rho - rho_h) * (-r2 * f) / (r2 + s(self.eta2))
    }

    /// Particle `i`'s `[ax, ay, az, d rho/dt]` (gravity added; zero acceleration for a wall
    /// or a fixed particle) and its stable step before the CFL factor, `min(sqrt(h / |a|), h /
    /// (c0 + visc_max))` (`f32::INFINITY` for a wall or a fixed particle); without
    /// `force_bound` (an imposed velocity) the acceleration does not bound the step.
    pub fn finish(&self, i: &Side, sum: &PairSum, force_bound: bool) -> ([f32; 4], f32) {
        let params = self.params;
        if !i.mobile || i.fixed {
            return ([0.0, 0.0, 0.0, sum.drho], f32::INFINITY);
        }
        let mut acc = sum.acc;
        for (a, g) in acc.iter_mut().zip(params.gravity) {
            *a += g;
        }
        let a = dot3(acc, acc).sqrt();
        let dt = stable_step(params.h, params.c0, a, force_bound, sum.visc_max);
        ([acc[0], acc[1], acc[2], sum.drho], dt)
    }
}

/// One force pass over all pairs closer than 2h.
///
/// Panics if the slices differ in length or a phase index is outside `params.phases`; both are
/// bugs of the caller, not bad input data.
pub fn interact(params: &Params, pos: &[[f32; 4]], vel_rho: &[[f32; 4]]) -> Interaction {
    interact_with_bed_walls(params, pos, vel_rho, &[])
}

/// [`interact`] with the particles `bed_walls[i]` (none past its end) standing as walls: the
/// held sediment of the Shields-only mode under the generalised wall condition
/// (`physics::boundary`), which then gets its density from the fluid around it as a wall does.
pub fn interact_with_bed_walls(
    params: &Params,
    pos: &[[f32; 4]],
    vel_rho: &[[f32; 4]],
    bed_walls: &[bool],
) -> Interaction {
    assert_eq!(
        pos.len(),
        vel_rho.len(),
        "positions and velocities differ in length"
    );
    let model = PairModel::new(params);
    let sides: Vec<Side> = pos
        .iter()
        .zip(vel_rho)
        .enumerate()
        .map(|(i, (p, v))| {
            let side = model.side(p, v);
            let wall = bed_walls.get(i).copied().unwrap_or(false);
            Side {
                mobile: side.mobile && !wall,
                ..side
            }
        })
        .collect();
    let mut forces = Vec::with_capacity(pos.len());
    let mut dt_limit = Vec::with_capacity(pos.len());
    for (i, side_i) in sides.iter().enumerate() {
        let mut sum = PairSum::default();
        for (j, side_j) in sides.iter().enumerate() {
            if j != i {
                model.add_pair(side_i, side_j, true, &mut sum);
            }
        }
        let (mut f, dt) = model.finish(side_i, &sum, true);
        if params.generalised_walls && !side_i.mobile {
            // A wall's fourth entry is then its density, not a rate.
            let mut wall = WallSums::default();
            for side_j in &sides {
                model.add_wall_pair(side_i, side_j, true, &mut wall);
            }
            f[3] = model.wall_density(side_i, &wall);
        }
        forces.push(f);
        dt_limit.push(dt);
    }
    Interaction { forces, dt_limit }
}

#[cfg(test)]
mod tests;
