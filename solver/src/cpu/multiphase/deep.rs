//! Held grains deep in a wet bed, spared the rheology's walk: the awake set under the water.
//!
//! A held grain whose kernel mass of sediment (Eq. 26) is at or over the surface threshold is
//! not at the bed's surface, nor at its top, whatever water is in reach. Where the held bed
//! stands as a wall (the Shields-only mode under the generalised condition), the flow picks
//! up of a held grain only at a rate (`pickup_per_s > 0`: van Rijn's, integrated or worn net
//! of what settles) and its viscosity does not depend on its strain (HBP m = 0, n = 1), its
//! rheology then takes nothing from its neighbours that its own start does not give
//! (`Rheology::finish` from `Rheology::start`): no shear stress, so no pick-up; no load passed
//! on; held, with no stress and `2 mu_s`. Only the kernel mass must be known, and its last walk
//! bounds it.
//!
//! The bound. Let the last walk find kernel mass `m_k = sum_j c_j / rho_j` over the sediment
//! j within 2h, `c_j = m_j^2 W_ij`, with no sediment in the cells within reach but held grains
//! at rest, and `i` itself held. Held grains at rest do not move, and a held grain the store
//! parks (one in a flume's collector or past its outlet) clears every record; sediment that
//! arrives since only adds to the sum, and sediment that leaves must first move, which wakes
//! the grain while it is within reach. So every `c_j` of that walk is still there, and
//! `m_now >= sum_j c_j / rho_max >= m_k rho_min / rho_max`, with `rho_min` the held grains'
//! least density at that walk and `rho_max` their largest now. The record a walk leaves is
//! `m_k rho_min / rho0`; the grain sleeps while `record rho0 / rho_max` is over the threshold
//! by [`SLACK`], which covers the sums' rounding in f32. Any other walk clears the record, and
//! so does a word set from outside, or the grain parked or placed.

use super::super::grid::{Flagged, Grid};
use crate::physics::Params;
use crate::physics::interaction::phase_index;
use crate::physics::sediment::pass::{REGION_HELD, Rheology, SedimentModel};

/// Relative margin of a sleeper's kernel mass over the threshold: some forty sums of f32
/// round by under 1e-5.
const SLACK: f64 = 1e-4;

/// No record: the grain walks.
pub const NO_RECORD: f32 = f32::NAN;

/// What decides, this pass, which held grains under the water sleep.
pub struct Deep {
    /// Sediment that is not held at rest: any of it in reach may change a kernel mass.
    moving: Flagged,
    /// The least record a grain may sleep with now: the threshold times `rho_max / rho0`.
    least: f64,
    /// What a walk's kernel mass is multiplied by for its record: `rho_min / rho0`.
    to_record: f64,
}

impl Deep {
    /// The rule for a pass over particles at `pos`, `vel` with region words `words` (sorted
    /// order); None where it does not hold (see the module doc).
    pub fn new(
        params: &Params,
        model: &SedimentModel,
        pass: &Rheology,
        (pos, vel): (&[[f32; 4]], &[[f32; 4]]),
        words: &[u32],
    ) -> Option<Deep> {
        let mat = &model.material;
        let applies = params.generalised_walls
            && model.shields_only
            && model.pickup_per_s > 0.0
            && mat.hbp_m == 0.0
            && mat.hbp_n == 1.0;
        if !applies {
            return None;
        }
        let sand = |k: usize| phase_index(&pos[k]) == model.sediment_phase;
        let rests = |k: usize| {
            words[k] & REGION_HELD != 0 && vel[k][..3].iter().all(|&v| v == 0.0) && sand(k)
        };
        let moving = Flagged::new(words.len(), |k| sand(k) && !rests(k));
        let (mut lo, mut hi) = (f32::INFINITY, 0.0f32);
        for k in (0..words.len()).filter(|&k| rests(k)) {
            (lo, hi) = (lo.min(vel[k][3]), hi.max(vel[k][3]));
        }
        let rho0 = f64::from(params.phases[model.sediment_phase].rho0);
        let threshold = f64::from(pass.reference_mass()) * (1.0 + SLACK);
        Some(Deep {
            moving,
            least: threshold * f64::from(hi) / rho0,
            to_record: f64::from(lo) / rho0,
        })
    }

    /// Whether no sediment but held grains at rest lies in the cells within reach of `x`.
    pub fn quiet(&self, grid: &Grid, x: &[f32; 3]) -> bool {
        !grid.any_near(&self.moving, x)
    }

    /// Whether a quiet held grain whose last walk left `record` sleeps.
    pub fn sleeps(&self, record: f32) -> bool {
        f64::from(record) >= self.least
    }

    /// The record a quiet held grain's walk leaves from its kernel mass.
    pub fn record(&self, kernel_mass: f32) -> f32 {
        (f64::from(kernel_mass) * self.to_record) as f32
    }
}
