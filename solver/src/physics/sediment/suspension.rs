//! Suspension and the five flow regions (Zubeldia et al. 2018, Section 2.5.4, Eqs. 32-33 and
//! Figure 2; Fourtakas & Rogers 2016):
//! - volumetric concentration (Eq. 32):
//!   `c_v,i = sum_{j sediment} m_j / rho_j / sum_{j all} m_j / rho_j` over the kernel support
//!   r < 2h;
//! - Vand (1948) viscosity of suspended sediment (Eq. 33): `mu_w exp(2.5 c_v / (1 - (39/64) c_v))`;
//! - the regions: 1 un-yielded and 2 yielded sediment (HBP with Drucker-Prager's tau_y), 3 bed
//!   load (HBP with Shields' tau_bcr), 4 suspended (Vand), 5 water (mu_w).

use super::SedimentParams;
use super::drucker_prager::yields;
use super::rheology::hbp_viscosity;
use crate::physics::lanes::Real;

/// Volumetric concentration below which a yielded sediment particle is suspended (Section 2.5.3:
/// "the threshold for the onset of suspended transport is set to c_v,i < 0.3").
pub const SUSPENSION_CONCENTRATION: f32 = 0.3;

/// Volumetric concentration of Eq. 32 from its two kernel-volume sums `sum_j m_j / rho_j` over
/// r < 2h (m3, or m2 in 2-D): `sediment_volume` over sediment neighbours, `total_volume` over all
/// of them. Dimensionless, in [0, 1].
///
/// Both sums include the particle itself (r = 0 < 2h). The paper's "all" is read as the two
/// material phases, water and sediment: wall (DBC) particles are not part of the mixture, and
/// counting them would dilute the bed next to the flume floor into "suspension". That choice is
/// the caller's, who builds the sums. With no volume at all (a caller bug: i itself counts) the
/// concentration is 0.
pub fn volume_fraction(sediment_volume: f32, total_volume: f32) -> f32 {
    if total_volume > 0.0 {
        (sediment_volume / total_volume).clamp(0.0, 1.0)
    } else {
        0.0
    }
}

/// Vand viscosity of Eq. 33, Pa s: `mu_w exp(2.5 c_v / (1 - (39/64) c_v))`, with mu_w the water
/// viscosity (Pa s) and c_v the volumetric concentration (dimensionless; finite for c_v < 64/39,
/// so for every concentration in [0, 1]).
pub fn vand_viscosity(c_v: f32, mu_w: f32) -> f32 {
    mu_w * (2.5 * c_v / (1.0 - 39.0 / 64.0 * c_v)).exp()
}

/// The flow regions of Figure 1, numbered as in the paper (`region as u32` gives the number).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[repr(u32)]
pub enum Region {
    /// Sediment below its Drucker-Prager yield stress; its HBP viscosity with tau_c = tau_y is
    /// large, so it barely moves.
    Unyielded = 1,
    /// Sediment above its Drucker-Prager yield stress; HBP with tau_c = tau_y.
    Yielded = 2,
    /// Surface sediment with `tau_b > tau_bcr` (Eq. 25): bed load, HBP with tau_c = tau_bcr.
    BedLoad = 3,
    /// Yielded or bed-load sediment with `c_v < 0.3`: Vand viscosity (Eq. 33).
    Suspended = 4,
    /// Water: Newtonian with mu_w (Eq. 11).
    Water = 5,
}

/// Region of one particle by the flow chart of Figure 2.
///
/// - `is_sediment`: false for water (walls are not classified);
/// - `at_surface`: the surface test of Eq. 26
///   ([`is_surface`](super::shields::is_surface));
/// - `tau_b`, `tau_bcr`: bed shear stress and its critical value on the local slope (Eqs. 18, 24),
///   Pa; read only at the surface;
/// - `sqrt_j2`, `tau_y`: the stress invariant and the Drucker-Prager yield stress (Eqs. 30-31), Pa;
/// - `c_v`: volumetric concentration (Eq. 32).
///
/// A surface particle with `tau_b > tau_bcr` is bed load (3); any other sediment particle is
/// yielded (2) or not (1) by Drucker-Prager; then a yielded or bed-load particle with
/// `c_v < 0.3` is suspended (4). Un-yielded sediment is never suspended: Section 2.5.4 speaks of
/// "a yielded sediment particle" below the threshold.
pub fn classify(
    is_sediment: bool,
    at_surface: bool,
    tau_b: f32,
    tau_bcr: f32,
    sqrt_j2: f32,
    tau_y: f32,
    c_v: f32,
) -> Region {
    if !is_sediment {
        return Region::Water;
    }
    let region = if at_surface && tau_b > tau_bcr {
        Region::BedLoad
    } else if yields(sqrt_j2, tau_y) {
        Region::Yielded
    } else {
        Region::Unyielded
    };
    if region != Region::Unyielded && c_v < SUSPENSION_CONCENTRATION {
        Region::Suspended
    } else {
        region
    }
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

/// What the rheology pass chooses a sediment particle's region from.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RegionInputs {
    /// The Shields-only mode (the rest held), or Drucker-Prager with Shields.
    pub shields_only: bool,
    /// Held after the previous pass.
    pub held_before: bool,
    /// The surface test of Eq. 26.
    pub at_surface: bool,
    /// Bed shear stress and its critical value on the local slope, Pa.
    pub tau_b: f32,
    pub tau_bcr: f32,
    /// The stress invariant the particle carries and its Drucker-Prager yield stress, Pa.
    pub sqrt_j2: f32,
    pub tau_y: f32,
    /// Volumetric concentration (Eq. 32).
    pub c_v: f32,
    /// Whether the particle's mass has been picked up this step ([`super::pickup`]); always
    /// true where Shields releases at once, as the paper does.
    pub picked_up: bool,
    /// No solid (sediment or wall) lies beside it at its own level ([`level_solid`]), and the
    /// case holds a grain again only beside one (`config::ComesToRest::BesideASolid`).
    pub lone: bool,
}

/// Whether a solid neighbour at `x_ij` from a sediment particle (`up` its vertical component,
/// `r2` its squared length) lies beside it at its own level: within half a particle spacing
/// `dp` of its height and one and a half spacings of it, the nearest neighbours of a row
/// and not those of the rows above and below.
#[inline(always)]
pub fn level_solid<L: Real>(up: L, r2: L, dp: f32) -> L::Mask {
    (up * up).lt(L::splat(0.25 * dp * dp)) & r2.lt(L::splat(2.25 * dp * dp))
}

/// A sediment particle's region as the rheology pass chooses it: [`classify_shields_only`] in
/// that mode; in the Drucker-Prager mode a particle held before stays un-yielded unless
/// Shields makes it bed load (only [`super::hold::release_pass`] frees it otherwise), and any
/// other is classified by Figure 2 ([`classify`]). In either mode a particle held before that
/// has not been picked up stays held: Shields' release waits for the pick-up, and so does
/// suspension (a top row thinned by the pick-ups would otherwise fall below the concentration
/// of suspension at once, and the water reach the floor through it). In either mode a grain
/// not held before with no solid beside it at its level (`lone`, which the rheology pass sets
/// only under `comes_to_rest: beside_a_solid`) is bed load where it would be held: a rule the
/// paper does not state, measured in the README's levels section. The GPU's `sediment_region`
/// in `shaders/common/sediment.wgsl` is compared with it input by input
/// (`tests/wgsl_functions.rs`).
pub fn sediment_region(r: &RegionInputs) -> Region {
    if r.held_before && !r.picked_up {
        return Region::Unyielded;
    }
    let region = if r.shields_only {
        classify_shields_only(r.at_surface, r.tau_b, r.tau_bcr, r.c_v)
    } else if r.held_before && !(r.at_surface && r.tau_b > r.tau_bcr) {
        Region::Unyielded
    } else {
        classify(
            true,
            r.at_surface,
            r.tau_b,
            r.tau_bcr,
            r.sqrt_j2,
            r.tau_y,
            r.c_v,
        )
    };
    // A grain coming to rest with no solid beside it at its own level lies on the bed, not in
    // it: no skeleton confines it, and at a few particles of depth one such grain held on the
    // bed's top is a step that dams the flow. It stays bed load until it comes to rest in a row.
    if region == Region::Unyielded && r.lone && !r.held_before {
        Region::BedLoad
    } else {
        region
    }
}

/// Apparent viscosity of a particle in `region`, Pa s, with `ii_d` the second invariant of its
/// strain rate (1/s2), `tau_y` and `tau_bcr` its Drucker-Prager and Shields yield stresses (Pa)
/// and `c_v` its concentration:
/// - 1 and 2: HBP (Eq. 15) with tau_c = tau_y. The two share the formula; the paper lets the
///   difference emerge from tau_y growing with depth rather than switching laws;
/// - 3: HBP with tau_c = tau_bcr;
/// - 4: Vand (Eq. 33);
/// - 5: mu_w.
pub fn apparent_viscosity(
    region: Region,
    ii_d: f32,
    tau_y: f32,
    tau_bcr: f32,
    c_v: f32,
    params: &SedimentParams,
) -> f32 {
    let hbp = |tau_c: f32| hbp_viscosity(ii_d, tau_c, params.hbp_m, params.hbp_n, params.mu_s_pa_s);
    match region {
        Region::Unyielded | Region::Yielded => hbp(tau_y),
        Region::BedLoad => hbp(tau_bcr),
        Region::Suspended => vand_viscosity(c_v, params.mu_w),
        Region::Water => params.mu_w,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn louvain() -> SedimentParams {
        SedimentParams {
            rho_s: 1270.0,
            d50_m: 3.5e-3,
            phi_rad: 31.0_f32.to_radians(),
            cohesion_pa: 0.0,
            hbp_m: 100.0,
            hbp_n: 1.2,
            mu_s_pa_s: 0.1,
            ks_over_d50: 5.0,
            surface_mass_fraction: 0.9,
            rho_w: 1000.0,
            nu_w: 1.0e-6,
            mu_w: 1.0e-3,
        }
    }

    #[test]
    fn concentration() {
        assert_eq!(volume_fraction(3.0, 4.0), 0.75);
        assert_eq!(volume_fraction(0.0, 4.0), 0.0);
        assert_eq!(volume_fraction(4.0, 4.0), 1.0);
        // Rounding can put the sediment sum a hair above the total.
        assert_eq!(volume_fraction(4.000_001, 4.0), 1.0);
        assert_eq!(volume_fraction(0.0, 0.0), 0.0);
    }

    #[test]
    fn vand_by_hand() {
        assert_eq!(vand_viscosity(0.0, 1e-3), 1e-3);
        // c_v = 0.3: 0.75 / (1 - 0.3 * 39/64) = 0.75 / 0.8171875 = 0.9177820;
        // exp(0.9177820) = 2.5037310, times mu_w = 1e-3.
        let mu = vand_viscosity(0.3, 1e-3);
        assert!((mu - 2.503_731e-3).abs() < 1e-6 * 2.503_731e-3, "{mu}");
        // c_v = 0.1: exp(0.25 / 0.9390625) = 1.3050260.
        let mu = vand_viscosity(0.1, 1.0);
        assert!((mu - 1.305_026).abs() < 1e-6, "{mu}");
        // Finite over the whole range of concentrations.
        assert!(vand_viscosity(1.0, 1e-3).is_finite());
    }

    #[test]
    fn classification_follows_the_flow_chart() {
        let dense = 0.6;
        let thin = 0.1;
        // Water is water whatever the rest says.
        assert_eq!(
            classify(false, true, 9.0, 1.0, 9.0, 1.0, thin),
            Region::Water
        );
        // Surface, tau_b > tau_bcr: bed load, even where Drucker-Prager would hold.
        assert_eq!(
            classify(true, true, 2.0, 1.0, 0.0, 5.0, dense),
            Region::BedLoad
        );
        // Surface below the Shields threshold (equality included): Drucker-Prager decides.
        assert_eq!(
            classify(true, true, 1.0, 1.0, 0.0, 5.0, dense),
            Region::Unyielded
        );
        assert_eq!(
            classify(true, true, 0.5, 1.0, 6.0, 5.0, dense),
            Region::Yielded
        );
        // Below the surface tau_b is not looked at.
        assert_eq!(
            classify(true, false, 9.0, 1.0, 0.0, 5.0, dense),
            Region::Unyielded
        );
        assert_eq!(
            classify(true, false, 9.0, 1.0, 6.0, 5.0, dense),
            Region::Yielded
        );
        // Thin yielded or bed-load sediment is suspended; un-yielded never is.
        assert_eq!(
            classify(true, true, 2.0, 1.0, 0.0, 5.0, thin),
            Region::Suspended
        );
        assert_eq!(
            classify(true, false, 0.0, 1.0, 6.0, 5.0, thin),
            Region::Suspended
        );
        assert_eq!(
            classify(true, false, 0.0, 1.0, 0.0, 5.0, thin),
            Region::Unyielded
        );
        // The threshold is strict: c_v = 0.3 is not suspended.
        assert_eq!(
            classify(true, false, 0.0, 1.0, 6.0, 5.0, 0.3),
            Region::Yielded
        );
        assert_eq!(Region::BedLoad as u32, 3);
        assert_eq!(Region::Water as u32, 5);
    }

    #[test]
    fn viscosity_by_region() {
        let p = louvain();
        let (ii_d, tau_y, tau_bcr, c_v) = (1.0_f32, 10.0_f32, 0.5_f32, 0.2_f32);
        // HBP at II_D = 1: tau_c (1 - e^-100) + 0.2 * 4^0.1 = tau_c + 0.229739671.
        let power = 0.229_739_67;
        let mu1 = apparent_viscosity(Region::Unyielded, ii_d, tau_y, tau_bcr, c_v, &p);
        let mu2 = apparent_viscosity(Region::Yielded, ii_d, tau_y, tau_bcr, c_v, &p);
        assert_eq!(mu1, mu2);
        assert!((mu1 - (10.0 + power)).abs() < 1e-5, "{mu1}");
        let mu3 = apparent_viscosity(Region::BedLoad, ii_d, tau_y, tau_bcr, c_v, &p);
        assert!((mu3 - (0.5 + power)).abs() < 1e-6, "{mu3}");
        let mu4 = apparent_viscosity(Region::Suspended, ii_d, tau_y, tau_bcr, c_v, &p);
        assert_eq!(mu4, vand_viscosity(c_v, 1e-3));
        let mu5 = apparent_viscosity(Region::Water, ii_d, tau_y, tau_bcr, c_v, &p);
        assert_eq!(mu5, 1e-3);
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

    /// A held particle Shields would release, or whose concentration is that of suspension,
    /// waits for its pick-up in either mode; one that was moving goes on moving, picked or not.
    #[test]
    fn held_bed_waits_for_its_pickup() {
        let base = RegionInputs {
            shields_only: true,
            held_before: true,
            at_surface: true,
            tau_b: 0.5,
            tau_bcr: 0.2,
            sqrt_j2: 0.0,
            tau_y: 10.0,
            c_v: 0.6,
            picked_up: false,
            lone: false,
        };
        for shields_only in [true, false] {
            let r = RegionInputs {
                shields_only,
                ..base
            };
            assert_eq!(sediment_region(&r), Region::Unyielded, "{r:?}");
            let thin = RegionInputs { c_v: 0.1, ..r };
            assert_eq!(sediment_region(&thin), Region::Unyielded, "{thin:?}");
            let picked = RegionInputs {
                picked_up: true,
                ..r
            };
            assert_eq!(sediment_region(&picked), Region::BedLoad, "{picked:?}");
            let moving = RegionInputs {
                held_before: false,
                ..r
            };
            assert_eq!(sediment_region(&moving), Region::BedLoad, "{moving:?}");
        }
    }

    /// A grain coming to rest on the bed's top with nothing beside it is not held; one in a
    /// row is, and so is one the bed held already, lone or not, in either mode.
    #[test]
    fn a_lone_grain_coming_to_rest_is_not_held() {
        for shields_only in [true, false] {
            let resting = RegionInputs {
                shields_only,
                held_before: false,
                at_surface: true,
                tau_b: 0.1,
                tau_bcr: 0.2,
                sqrt_j2: 1.0,
                tau_y: 10.0,
                c_v: 0.6,
                picked_up: true,
                lone: false,
            };
            assert_eq!(sediment_region(&resting), Region::Unyielded, "{resting:?}");
            let lone = RegionInputs {
                lone: true,
                ..resting
            };
            assert_eq!(sediment_region(&lone), Region::BedLoad, "{lone:?}");
            let held = RegionInputs {
                held_before: true,
                ..lone
            };
            assert_eq!(sediment_region(&held), Region::Unyielded, "{held:?}");
            let waiting = RegionInputs {
                picked_up: false,
                ..held
            };
            assert_eq!(sediment_region(&waiting), Region::Unyielded, "{waiting:?}");
        }
    }

    /// The neighbours of a square lattice's row are beside a grain; those of the rows above
    /// and below, straight or diagonal, are not.
    #[test]
    fn the_row_beside_a_grain() {
        let dp = 0.01;
        assert!(level_solid(0.0, dp * dp, dp));
        assert!(level_solid(0.3 * dp, 1.1 * dp * dp, dp));
        assert!(!level_solid(dp, dp * dp, dp));
        assert!(!level_solid(dp, 2.0 * dp * dp, dp));
        assert!(!level_solid(0.0, 4.0 * dp * dp, dp));
    }
}
