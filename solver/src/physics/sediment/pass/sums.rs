//! What the rheology pass carries per particle, one or eight lanes of them: the sums a particle
//! gathers from its neighbours and the side it shows them.

use crate::physics::lanes::{Lanes, Real, pack};

/// Sums a particle (or [`LANES`](crate::physics::lanes::LANES) of them) gathers from its
/// neighbours in the rheology pass.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RheologySums<L: Real = f32> {
    /// `grad[a][b] = sum_j V_j (u_j - u_i)_a (grad_i W_ij)_b` (Eq. 13).
    pub(super) grad: [[L; 3]; 3],
    pub(super) sediment_volume: L,
    pub(super) mixture_volume: L,
    pub(super) kernel_mass: L,
    /// `-sum_solid V_j grad_i W_ij` over sediment and walls: the bed's outward normal.
    pub(super) normal: [L; 3],
    /// Distance to the nearest water particle (infinite: none in reach) and its velocity,
    /// relative to this one or its own (`SedimentModel::water_speed`).
    pub(super) water_r: L,
    pub(super) water_u: [L; 3],
    /// Solid neighbours (sediment, walls) beside it at its own level
    /// ([`level_solid`](crate::physics::sediment::suspension::level_solid)).
    pub(super) level_solids: L,
}

impl<L: Real> Default for RheologySums<L> {
    fn default() -> Self {
        let zero = L::splat(0.0);
        RheologySums {
            grad: [[zero; 3]; 3],
            sediment_volume: zero,
            mixture_volume: zero,
            kernel_mass: zero,
            normal: [zero; 3],
            water_r: L::splat(f32::INFINITY),
            water_u: [zero; 3],
            level_solids: zero,
        }
    }
}

impl RheologySums {
    /// The kernel mass of sediment around the particle, kg (Eq. 26's, with its own).
    pub fn kernel_mass(&self) -> f32 {
        self.kernel_mass
    }
}

impl RheologySums<Lanes> {
    /// The sums `sums` side by side ([`pack`]).
    #[inline(always)]
    pub fn lanes(sums: &[RheologySums]) -> RheologySums<Lanes> {
        pack(sums, |out: &mut RheologySums<Lanes>, k, s| {
            for a in 0..3 {
                for b in 0..3 {
                    out.grad[a][b].0[k] = s.grad[a][b];
                }
                out.normal[a].0[k] = s.normal[a];
                out.water_u[a].0[k] = s.water_u[a];
            }
            out.sediment_volume.0[k] = s.sediment_volume;
            out.mixture_volume.0[k] = s.mixture_volume;
            out.kernel_mass.0[k] = s.kernel_mass;
            out.water_r.0[k] = s.water_r;
            out.level_solids.0[k] = s.level_solids;
        })
    }

    /// The sums of lane `k`.
    #[inline(always)]
    pub fn lane(&self, k: usize) -> RheologySums {
        RheologySums {
            grad: self.grad.map(|row| row.map(|g| g.0[k])),
            sediment_volume: self.sediment_volume.0[k],
            mixture_volume: self.mixture_volume.0[k],
            kernel_mass: self.kernel_mass.0[k],
            normal: self.normal.map(|n| n.0[k]),
            water_r: self.water_r.0[k],
            water_u: self.water_u.map(|u| u.0[k]),
            level_solids: self.level_solids.0[k],
        }
    }
}

/// A particle (or lanes of them) as the rheology pass sees it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RheologySide<L: Real = f32> {
    pub x: [L; 3],
    pub v: [L; 3],
    pub sediment: L::Mask,
}

impl RheologySide<Lanes> {
    /// The sides `sides` side by side ([`pack`]).
    #[inline(always)]
    pub fn lanes(sides: &[RheologySide]) -> RheologySide<Lanes> {
        pack(sides, |out: &mut RheologySide<Lanes>, k, s| {
            for a in 0..3 {
                out.x[a].0[k] = s.x[a];
                out.v[a].0[k] = s.v[a];
            }
            out.sediment.0[k] = if s.sediment { u32::MAX } else { 0 };
        })
    }
}
