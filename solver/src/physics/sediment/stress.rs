//! The viscous part of the momentum equation (Eq. 10 with sigma = -p I + tau), pair by pair,
//! with the stresses of the rheology pass ([`super::pass`]).

use super::pass::ParticleRheology;
use super::rheology::Tensor3;
use crate::physics::Params;
use crate::physics::interaction::{PairGeometry, phase_index, wall_scale};
use crate::physics::kernel::Wendland;
use crate::physics::lanes::{Lanes, Real, pack};

/// A particle (or [`LANES`](crate::physics::lanes::LANES) of them) as the stress divergence
/// sees it: position, phase and `tau / rho^2`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StressSide<L: Real = f32> {
    pub x: [L; 3],
    pub phase: L::Index,
    pub tau_over_rho2: [[L; 3]; 3],
}

impl StressSide<Lanes> {
    /// The stress sides `sides` side by side ([`pack`]).
    #[inline(always)]
    pub fn lanes(sides: &[StressSide]) -> StressSide<Lanes> {
        pack(sides, |out: &mut StressSide<Lanes>, k, s| {
            for a in 0..3 {
                out.x[a].0[k] = s.x[a];
                for b in 0..3 {
                    out.tau_over_rho2[a][b].0[k] = s.tau_over_rho2[a][b];
                }
            }
            out.phase[k] = s.phase;
        })
    }
}

/// `sum_j m_j (tau_i / rho_i^2 + tau_j / rho_j^2) . grad_i W_ij`, m/s2, for a mobile particle
/// with the stresses of [`super::pass::rheology_pass`]; a wall neighbour's mass is scaled by
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
    pub fn add_pair(&self, i: &StressSide, j: &StressSide, acc: &mut [f32; 3]) {
        self.add_pair_as(i, (j, false), acc);
    }

    /// [`StressDivergence::add_pair`] with j a wall whatever its phase when `bed_wall`.
    fn add_pair_as(&self, i: &StressSide, (j, bed_wall): (&StressSide, bool), acc: &mut [f32; 3]) {
        let x_ij = [i.x[0] - j.x[0], i.x[1] - j.x[1], i.x[2] - j.x[2]];
        let r2 = x_ij[0] * x_ij[0] + x_ij[1] * x_ij[1] + x_ij[2] * x_ij[2];
        if r2 >= self.support2 || r2 < self.coincident2 {
            return;
        }
        let phases = &self.params.phases;
        let phase_j = &phases[j.phase as usize];
        let m_j = if phase_j.mobile && !bed_wall {
            phase_j.mass
        } else {
            phase_j.mass * wall_scale(phases[i.phase as usize].rho0, phase_j.rho0)
        };
        let f = self.kernel.grad_factor(r2.sqrt());
        let valid = true;
        self.add_term(
            i,
            j,
            &PairGeometry {
                x_ij,
                f,
                m_j,
                valid,
            },
            acc,
        );
    }

    /// The term itself, in the lanes where the pair's geometry (`PairModel::add_pair`'s) is
    /// valid.
    #[inline(always)]
    pub fn add_term<L: Real>(
        &self,
        i: &StressSide<L>,
        j: &StressSide,
        g: &PairGeometry<L>,
        acc: &mut [L; 3],
    ) {
        // The dimension a constant, as in `Rheology::add_pair_of_volume`.
        if self.params.dim == 2 {
            Self::add_term_in::<L, 2>(i, j, g, acc);
        } else {
            Self::add_term_in::<L, 3>(i, j, g, acc);
        }
    }

    /// [`StressDivergence::add_term`] in `D` dimensions.
    #[inline(always)]
    fn add_term_in<L: Real, const D: usize>(
        i: &StressSide<L>,
        j: &StressSide,
        g: &PairGeometry<L>,
        acc: &mut [L; 3],
    ) {
        // In 2-D the third row and column are zero: the loops stop at the dimension.
        let rows = acc.iter_mut().zip(&i.tau_over_rho2).zip(&j.tau_over_rho2);
        for ((a, t_i), t_j) in rows.take(D) {
            for ((&ti, &tj), x) in t_i.iter().zip(t_j).zip(g.x_ij).take(D) {
                *a = L::select(g.valid, *a + g.m_j * (ti + L::splat(tj)) * x * g.f, *a);
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
    stress_divergence_with_bed_walls(params, pos, vel_rho, rheology, &[])
}

/// [`stress_divergence`] with the particles `bed_walls[i]` (none past its end) standing as walls
/// (`interaction::interact_with_bed_walls`): zero for them, and their mass scaled as a wall's
/// in their neighbours' terms.
pub fn stress_divergence_with_bed_walls(
    params: &Params,
    pos: &[[f32; 4]],
    vel_rho: &[[f32; 4]],
    rheology: &[ParticleRheology],
    bed_walls: &[bool],
) -> Vec<[f32; 3]> {
    let div = StressDivergence::new(params);
    let sides: Vec<StressSide> = (0..pos.len())
        .map(|i| div.side(&pos[i], vel_rho[i][3], &rheology[i].stress))
        .collect();
    let wall = |i: usize| bed_walls.get(i).copied().unwrap_or(false);
    (0..pos.len())
        .map(|i| {
            let mut acc = [0.0_f32; 3];
            if params.phases[phase_index(&pos[i])].mobile && !wall(i) {
                for (j, side_j) in sides.iter().enumerate() {
                    div.add_pair_as(&sides[i], (side_j, wall(j)), &mut acc);
                }
            }
            acc
        })
        .collect()
}
