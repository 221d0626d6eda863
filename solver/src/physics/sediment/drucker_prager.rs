//! Drucker-Prager yield criterion of the sub-surface sediment (Zubeldia et al. 2018, Eqs. 27-31;
//! Fourtakas & Rogers 2016):
//! - cone parameters from the Mohr-Coulomb ones (Eq. 29):
//!   `alpha = 2 sin(phi) / (sqrt(3) (3 - sin(phi)))`,
//!   `kappa_c = 6 c cos(phi) / (sqrt(3) (3 - sin(phi)))`;
//! - yield stress (Eq. 31): `tau_y = alpha p + kappa_c`;
//! - the particle yields when `sqrt(J2) > tau_y` (Eq. 30).
//!
//! Eq. 29 is the paper's matching (the Drucker-Prager cone through the compressive meridian of the
//! Mohr-Coulomb pyramid). Other codes use other matchings, for example the plane-strain
//! `alpha = tan(phi) / sqrt(9 + 12 tan^2(phi))`; this file implements Eq. 29 only.
//!
//! The paper calls p "J1, the sediment skeleton pressure" although the trace of the stress tensor
//! would be -3p; like MODEL.md, the code takes p itself, positive in compression. The caller
//! chooses which pressure that is (Fourtakas & Rogers use the skeleton pressure, the sediment
//! particle's pressure less the pore water pressure).

/// Friction coefficient alpha of Eq. 29 (dimensionless), phi the internal friction angle in rad.
pub fn alpha(phi: f32) -> f32 {
    let s = phi.sin();
    2.0 * s / (3.0_f32.sqrt() * (3.0 - s))
}

/// Cohesion term kappa_c of Eq. 29, Pa; `cohesion` c in Pa, phi in rad.
pub fn kappa_c(phi: f32, cohesion: f32) -> f32 {
    let s = phi.sin();
    6.0 * cohesion * phi.cos() / (3.0_f32.sqrt() * (3.0 - s))
}

/// Yield stress `tau_y = alpha p + kappa_c` of Eq. 31, Pa; `p` in Pa, positive in compression.
///
/// A negative p is read as zero: a granular skeleton in tension has lost grain contacts and with
/// them its frictional strength, so only the cohesion is left. Without the clamp, tension would
/// give a negative yield stress and, through Eq. 15, a negative viscosity.
pub fn yield_stress(alpha: f32, kappa_c: f32, p: f32) -> f32 {
    alpha * p.max(0.0) + kappa_c
}

/// Eq. 30: the particle yields when `sqrt(J2) > tau_y` (strictly; at equality it holds).
pub fn yields(sqrt_j2: f32, tau_y: f32) -> bool {
    sqrt_j2 > tau_y
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

#[cfg(test)]
mod tests {
    use super::*;

    const DEG: f32 = std::f32::consts::PI / 180.0;

    #[test]
    fn alpha_by_hand() {
        // Eq. 29 at phi = 30 deg: sin = 1/2, 2 * 0.5 / (sqrt(3) * 2.5) = 1 / 4.330127 = 0.230940.
        let a = alpha(30.0 * DEG);
        assert!((a - 0.2309).abs() < 1e-4, "{a}");
        assert!((a - 0.230_940_1).abs() < 1e-6, "{a}");
        // Louvain PVC, phi = 31 deg: sin = 0.515038, 1.030076 / (1.732051 * 2.484962) = 0.239326.
        let a = alpha(31.0 * DEG);
        assert!((a - 0.239_326).abs() < 1e-5, "{a}");
        assert_eq!(alpha(0.0), 0.0);
    }

    #[test]
    fn kappa_by_hand() {
        assert_eq!(kappa_c(30.0 * DEG, 0.0), 0.0);
        // phi = 30 deg: 6 c (sqrt(3)/2) / (sqrt(3) * 2.5) = 1.2 c.
        let k = kappa_c(30.0 * DEG, 1000.0);
        assert!((k - 1200.0).abs() < 1e-3, "{k}");
    }

    #[test]
    fn yield_stress_and_tension_cutoff() {
        let (a, k) = (alpha(30.0 * DEG), kappa_c(30.0 * DEG, 1000.0));
        let ty = yield_stress(a, k, 5000.0);
        assert!((ty - (0.230_940_1 * 5000.0 + 1200.0)).abs() < 1e-2, "{ty}");
        // Tension: only the cohesion is left; cohesionless sand has no strength at all.
        assert_eq!(yield_stress(a, k, -5000.0), k);
        assert_eq!(yield_stress(a, 0.0, -1.0), 0.0);
        assert_eq!(yield_stress(a, 0.0, 0.0), 0.0);
    }

    #[test]
    fn yields_strictly_above() {
        assert!(yields(1.0001, 1.0));
        assert!(!yields(1.0, 1.0));
        assert!(!yields(0.5, 1.0));
        // Cohesionless sediment at zero pressure yields under any shear.
        assert!(yields(1e-9, yield_stress(alpha(0.5), 0.0, 0.0)));
    }

    #[test]
    fn skeleton_pressure_is_effective_stress_at_the_surface() {
        // 5 cm below a bed surface that is the free surface: p = rho_s g d = 2710 * 9.81 * 0.05
        // = 1329.255 Pa; effective stress (rho_s - rho_w) g d = 1710 * 9.81 * 0.05 = 838.755 Pa.
        let p = skeleton_pressure(1329.255, 2710.0, 1000.0);
        assert!((p - 838.755).abs() < 1e-2, "{p}");
    }
}
