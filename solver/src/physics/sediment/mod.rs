//! CPU reference of the water-sediment scour model of Zubeldia et al. (2018): the sediment is a
//! saturated pseudo-Newtonian fluid whose yield stress comes from Drucker-Prager below the bed
//! surface and from Shields at the surface, with a suspension viscosity where the sediment thins
//! out.
//!
//! - [`rheology`]: strain rate, its second invariant and the Herschel-Bulkley-Papanastasiou
//!   apparent viscosity (Eqs. 12-15);
//! - [`drucker_prager`]: the pressure-dependent yield stress (Eqs. 27-31);
//! - [`shields`]: critical Shields parameter, log-law friction velocity, bed shear stress, slope
//!   factors and surface detection (Eqs. 16-26);
//! - [`suspension`]: volumetric concentration, Vand viscosity and the region classification of
//!   Figure 2 (Eqs. 32-33);
//! - [`pickup`]: van Rijn's (1984) pick-up rate, which releases a particle Shields would
//!   release at the rate the flow lifts its mass (an option; the paper releases it at once);
//! - [`pass`]: all of it for every particle, and [`hold`]: un-yielded sediment held at rest
//!   until Drucker-Prager releases it.
//!
//! Like the rest of [`crate::physics`], these are plain f32 functions over scalars and slices: the
//! oracle the GPU stages are tested against. Equation numbers are the paper's, as restored in
//! `shared/MODEL.md`.

pub mod drucker_prager;
pub mod hold;
pub mod infiltration;
pub mod pass;
pub mod pickup;
pub mod rheology;
pub mod shields;
pub mod stress;
pub mod suspension;

/// Material parameters of one sediment and of the water it lies in.
///
/// Nothing here is checked on construction; the functions document what they expect of each value
/// (for example `0 < phi_rad < pi/2`).
#[derive(Clone, Debug, PartialEq)]
pub struct SedimentParams {
    /// Saturated density of the sediment rho_s (grains plus pore water), kg/m3; enters the
    /// submerged weight of Eq. 16 and the eroded mass of Eq. 34.
    pub rho_s: f32,
    /// Median grain diameter d50, m (the d of Eqs. 16-17).
    pub d50_m: f32,
    /// Internal friction angle phi, rad (Eqs. 22-23, 29).
    pub phi_rad: f32,
    /// Cohesion c, Pa (Eq. 29).
    pub cohesion_pa: f32,
    /// Papanastasiou exponent m of Eq. 15, s: the larger, the closer to Bingham.
    pub hbp_m: f32,
    /// Power-law index n of Eq. 15, dimensionless: 1 Bingham/Newtonian, > 1 shear thickening,
    /// < 1 shear thinning.
    pub hbp_n: f32,
    /// Sediment viscosity mu_s of Eq. 15, Pa s (strictly Pa s^n, a consistency index, when
    /// n != 1).
    pub mu_s_pa_s: f32,
    /// Equivalent (Nikuradse) roughness over grain size, ks / d50, dimensionless (Eq. 21; the
    /// paper's best fit for its flume is 3).
    pub ks_over_d50: f32,
    /// Fraction m_f of the reference sediment mass below which a sediment particle's kernel mass
    /// sum marks it as near the bed surface (Eq. 26), dimensionless.
    pub surface_mass_fraction: f32,
    /// Water density rho_w, kg/m3 (Eqs. 16, 18).
    pub rho_w: f32,
    /// Kinematic viscosity of water nu, m2/s (Eqs. 17, 19-21).
    pub nu_w: f32,
    /// Dynamic viscosity of water mu_w, Pa s (Eqs. 11, 33). Kept apart from `nu_w` because the
    /// paper uses both; they should satisfy mu_w = rho_w nu_w.
    pub mu_w: f32,
}

impl SedimentParams {
    /// Equivalent roughness ks = (ks / d50) d50, m.
    pub fn ks_m(&self) -> f32 {
        self.ks_over_d50 * self.d50_m
    }
}

/// The ULBRA flume's sand (d50 0.4 mm, 2710 kg/m3, ks = 3 d50, HBP n = 1, m = 0) in water at
/// 20 C, with a friction angle of 32 deg: the sand the unit tests of both engines use.
#[cfg(test)]
pub(crate) fn flume_sand() -> SedimentParams {
    SedimentParams {
        rho_s: 2710.0,
        d50_m: 4e-4,
        phi_rad: 32f32.to_radians(),
        cohesion_pa: 0.0,
        hbp_m: 0.0,
        hbp_n: 1.0,
        mu_s_pa_s: 1e-3,
        ks_over_d50: 3.0,
        surface_mass_fraction: 0.8,
        rho_w: 1000.0,
        nu_w: 1e-6,
        mu_w: 1e-3,
    }
}
