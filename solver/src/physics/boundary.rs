//! The generalised wall boundary of Adami, Hu & Adams (2012, J. Comput. Phys. 231:7057): a
//! wall particle b takes the pressure the fluid around it has, extrapolated to where it
//! stands,
//!
//! `p_b = (sum_f p_f W_bf + g . sum_f rho_f (x_b - x_f) W_bf) / sum_f W_bf`   (Adami Eq. 27,
//! a boundary at rest),
//!
//! over its fluid neighbours f, and the density that gives p_b by its own phase's equation of
//! state. A dynamic boundary (DBC) instead integrates its
//! density from the fluid's approach, which holds the fluid about a dp off it (1-2 cm at the
//! twin's dp = 1 cm) and, next to a flow, ratchets up (measured on the held sand of the CI
//! flume: 2,734 to 2,783 kg/m3 in 40 s, eight times the weight of the water above it). Here
//! the boundary pushes back exactly as hard as the fluid presses, every step, with no memory.
//!
//! Held sediment in the paper's Shields-only mode takes it too: the paper holds the sand that is
//! not eroded as fixed boundary particles, and as a dynamic boundary it held the flow 2 dp off
//! the bed and pushed it up (its density by continuity ratcheting up to 8 times the weight of
//! the water above it). As a wall (`bed_is_boundary` in `cpu/step.rs`, `held_bed_is_wall` in
//! `params.wgsl`) it carries the water's weight with no gap. Under the paper's release at once
//! the flow then released the bed row after row down to the floor (measured on the CI flume,
//! dp = 1 cm, 60 s, in an earlier trial): the bed wants the release at the rate the flow picks
//! sand up (`sediment::pickup`). Drucker-Prager's held sand carries the bed's own stress and
//! keeps its density by continuity: its skeleton pressure needs the weight of the sand above it,
//! which a boundary condition would not give a particle with no fluid around it.
//!
//! A particle inside a lattice of such walls feels its own pressure all round: nothing stops
//! it. Water that got between two rows of the held bed (through a hole a pick-up left, or
//! skimming the dry bed at the front with no pressure) travelled through the bed, released the
//! sand it passed and fell through the floor (5 particles in 60 s of the CI flume). So under
//! this condition the held bed also pushes water that squeezes closer than 0.6 dp to it away,
//! with Monaghan's (1994) boundary force (`PairModel::add_contact`, `CONTACT_REACH`); most water
//! resting on the bed stands farther off and does not feel it (on the CI flume at 30 s, 5
//! water particles within 0.6 dp of held sand, none nearer than 0.5 dp).
//!
//! A wall particle with no fluid within 2h is dry: it takes rest density (p = 0), touching
//! nothing that reads it. The fluid particles of an inlet buffer are left out of the sums:
//! their velocity is imposed, and at the rest density they used to keep they dragged the walls
//! around the inlet to zero pressure (measured: water squeezed out of the buffer fell through
//! the apron under it, 149 particles by t = 8 s on the CI flume). Under this condition the
//! buffer's own density follows continuity (`cpu/store.rs`, `inlet_density`): at rest density
//! it pressed on the water in front with no pressure, and that water, driven into the apron
//! by the buffer behind it, ran through it too (a third of the inflow by 60 s).
//!
//! The force pass gathers the sums (`interaction::PairModel::add_wall_pair`) and gives a wall
//! its density in place of a rate; the integrators store it. A wall's density thus answers to
//! the fluid of the step before, as the GPU computes it in the same pass.

use super::lanes::{Lanes, Real};

/// The running sums of one wall particle (or of [`LANES`](super::lanes::LANES) of them):
/// `sum W`, `sum p W` and `sum rho (x_b - x_f) W` over its fluid neighbours.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct WallSums<L: Real = f32> {
    pub w: L,
    pub p_w: L,
    pub rho_r_w: [L; 3],
}

impl<L: Real> WallSums<L> {
    /// Adds, in the lanes `m`, a fluid neighbour of pressure `p_f` and density `rho_f` at
    /// `x_bf = x_b - x_f` from the wall, whose kernel value is `w`.
    #[inline(always)]
    pub fn add(&mut self, m: L::Mask, w: L, p_f: L, rho_f: L, x_bf: [L; 3]) {
        self.w = L::select(m, self.w + w, self.w);
        self.p_w = L::select(m, self.p_w + p_f * w, self.p_w);
        for (acc, x) in self.rho_r_w.iter_mut().zip(x_bf) {
            *acc = L::select(m, *acc + rho_f * x * w, *acc);
        }
    }
}

impl WallSums<Lanes> {
    /// The sums of lane `k`.
    #[inline(always)]
    pub fn lane(&self, k: usize) -> WallSums {
        WallSums {
            w: self.w.0[k],
            p_w: self.p_w.0[k],
            rho_r_w: self.rho_r_w.map(|r| r.0[k]),
        }
    }
}

impl WallSums {
    /// The wall's pressure under `gravity`, Pa; `None` when it is dry.
    pub fn pressure(&self, gravity: [f32; 3]) -> Option<f32> {
        if self.w <= 0.0 {
            return None;
        }
        let g = gravity;
        let hydro = g[0] * self.rho_r_w[0] + g[1] * self.rho_r_w[1] + g[2] * self.rho_r_w[2];
        Some((self.p_w + hydro) / self.w)
    }
}

/// The density of a phase of rest density `rho0` and Tait stiffness `b` whose pressure is
/// `p`, kg/m3 (the equation of state inverted); a tension of B or more gives 0.
pub fn density(p: f32, rho0: f32, b: f32) -> f32 {
    rho0 * (1.0 + p / b).max(0.0).powf(1.0 / 7.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::eos::{pressure, tait_b};
    use crate::physics::kernel::Wendland;

    /// Still water 3 cm deep over a wall whose face is at y = 0: a wall particle at
    /// y = -0.005 m takes the hydrostatic pressure of its own depth, rho g (0.03 + 0.005) =
    /// 343.4 Pa, whatever the fluid particles it sees.
    #[test]
    fn a_wall_under_still_water_takes_the_hydrostatic_pressure_at_its_depth() {
        let (rho0, g, depth, dp) = (1000.0f32, 9.81f32, 0.03f32, 0.01f32);
        let b = tait_b(10.0, rho0);
        let kernel = Wendland::new(0.017, 2);
        let x_b = [0.013f32, -0.005];
        let mut sums = WallSums::default();
        for i in 0..6 {
            for j in 0..3 {
                let x_f = [dp * i as f32, 0.005 + dp * j as f32];
                let p = rho0 * g * (depth - x_f[1]);
                // The density that gives the hydrostatic pressure, as the fluid has it.
                let rho = rho0 * (1.0 + p / b).powf(1.0 / 7.0);
                let r = [x_b[0] - x_f[0], x_b[1] - x_f[1], 0.0];
                let dist = (r[0] * r[0] + r[1] * r[1]).sqrt();
                if dist < 0.034 {
                    sums.add(true, kernel.w(dist), p, rho, r);
                }
            }
        }
        let p = sums.pressure([0.0, -g, 0.0]).expect("wet");
        let want = rho0 * g * (depth + 0.005);
        // Exact but for the hydrostatic term taking each fluid particle's density for rho0:
        // (rho_f - rho0) g (y_f - y_b), rho_f - rho0 <= rho0 p / (7 B) = 2.4 kg/m3 at 343 Pa
        // (B = 14,286 Pa), y_f - y_b <= 2h = 3.4 cm: 0.8 Pa at most. Without the term the wall
        // would take 112 Pa less; with it reversed, 224 Pa less.
        assert!((p - want).abs() < 0.8, "{p} against {want}");
        // The density that gives it back, for water and for sand.
        for rho0 in [1000.0, 2710.0] {
            let b = tait_b(10.0, rho0);
            let back = pressure(density(p, rho0, b), rho0, b);
            assert!(
                (back - p).abs() < 1e-3 * p,
                "rho0 {rho0}: {back} against {p}"
            );
        }
    }

    #[test]
    fn a_wall_with_no_fluid_in_reach_is_dry_and_a_masked_lane_adds_nothing() {
        let mut sums = WallSums::default();
        assert_eq!(sums.pressure([0.0, -9.81, 0.0]), None);
        sums.add(false, 1.0, 100.0, 1000.0, [0.0, -0.01, 0.0]);
        assert_eq!(sums, WallSums::default());
    }
}
