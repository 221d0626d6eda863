//! Particle state on the host and what its codes mean: the phase code each particle carries in
//! `positions[i].w`, where parked particles wait, and the region word of the rheology pass.
//! Callers ask a particle's kind here rather than decoding the bits themselves.

use crate::config::Case;
use crate::physics::sediment::pass::REGION_HELD;
use crate::physics::sediment::pickup::{EXNER_WHOLE, PICKUP_SHIFT, PICKUP_WHOLE, word_units};
use crate::physics::sediment::suspension::Region;

/// Phase index 0 on the GPU is the wall; case phase k is GPU phase k + 1.
pub const WALL_PHASE: u32 = 0;

/// GPU phase index of parked particles in an open flume: the one after the case's phases.
pub fn parked_phase(case: &Case) -> u32 {
    case.phases.len() as u32 + 1
}

/// Where parked particles wait in an open flume: a lattice of spots dp apart above the flume,
/// one per particle id, clear of the splash room above the walls by 4h, so that no parked
/// particle comes within a kernel support of the flow.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Parking {
    pub x0: f64,
    pub y0: f64,
    pub cols: u32,
    pub dp: f64,
}

impl Parking {
    pub fn new(case: &Case, h: f64) -> Parking {
        let dp = case.numerics.dp_m;
        let (lo, hi) = (&case.domain.min_m, &case.domain.max_m);
        let height = hi[1] - lo[1];
        Parking {
            x0: lo[0] + 0.5 * dp,
            y0: hi[1] + SPLASH_ROOM * height + 4.0 * h,
            cols: ((hi[0] - lo[0]) / dp).floor().max(1.0) as u32,
            dp,
        }
    }

    /// The spot of particle `id`, m.
    pub fn spot(&self, id: u32) -> [f32; 2] {
        [
            (self.x0 + f64::from(id % self.cols) * self.dp) as f32,
            (self.y0 + f64::from(id / self.cols) * self.dp) as f32,
        ]
    }

    /// Top of the spots of `n` particles, m.
    pub fn top(&self, n: u64) -> f64 {
        self.y0 + (n / u64::from(self.cols) + 1) as f64 * self.dp
    }
}

/// Room kept above a tank for splashes, as a fraction of its height (the neighbour grid covers
/// it; particles above the grid still live in its top row).
pub const SPLASH_ROOM: f64 = 0.25;

/// Particle state on the CPU, in the GPU's layout (see `contract`).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Particles {
    /// x, y, z (z = 0 in 2-D) and, in w, the phase code as f32 bits: read it with `phase`.
    pub positions: Vec<[f32; 4]>,
    /// Velocity x, y, z and, in w, the density in kg/m3.
    pub vel_rho: Vec<[f32; 4]>,
    /// Stable identity of each particle (its index at generation).
    pub ids: Vec<u32>,
}

impl Particles {
    pub fn len(&self) -> usize {
        self.positions.len()
    }
    pub fn is_empty(&self) -> bool {
        self.positions.is_empty()
    }
    /// The phase code of particle `i`: `WALL_PHASE` for a wall, k + 1 for the case's phase k,
    /// `parked_phase` for a particle parked out of an open flume's flow.
    pub fn phase(&self, i: usize) -> u32 {
        self.positions[i][3].to_bits()
    }
    pub fn is_wall(&self, i: usize) -> bool {
        self.phase(i) == WALL_PHASE
    }
}

/// A particle's region word (`Simulation::regions`), decoded. The backends keep the region in
/// the word's low byte, `REGION_HELD` above it and a held particle's worn units above that
/// (`PICKUP_SHIFT`), as `shaders/common/sediment.wgsl` does.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct ParticleRegion {
    /// The region of Figure 2; none for walls, for every particle of a case without the
    /// multiphase viscosity, and for sediment before the first step has classified it.
    pub region: Option<Region>,
    /// Sediment held fixed in the last rheology pass.
    pub held: bool,
    /// The bits above the hold, the share of a particle's mass a pick-up worn away has taken
    /// off it ([`ParticleRegion::worn`]): a held particle's; under `van_rijn_exner` also one
    /// the bed has released, which carries them; 0 for any other.
    pub worn_bits: u32,
}

impl ParticleRegion {
    pub fn from_word(word: u32) -> ParticleRegion {
        let region = match word & REGION_MASK {
            1 => Some(Region::Unyielded),
            2 => Some(Region::Yielded),
            3 => Some(Region::BedLoad),
            4 => Some(Region::Suspended),
            5 => Some(Region::Water),
            _ => None,
        };
        let held = word & REGION_HELD != 0;
        ParticleRegion {
            region,
            held,
            worn_bits: word >> PICKUP_SHIFT,
        }
    }

    /// The share of a particle's mass worn off it, in particles: under Exner's balance
    /// (`exner`, `van_rijn_exner`) net of what settled on it, negative where that is more, held
    /// or carried off the bed; else by the pick-up alone (`van_rijn_integrated`), of a held
    /// particle only.
    pub fn worn(&self, exner: bool) -> f64 {
        if !(exner || self.held) {
            return 0.0;
        }
        let units = word_units(self.worn_bits << PICKUP_SHIFT, exner);
        let whole = if exner { EXNER_WHOLE } else { PICKUP_WHOLE };
        f64::from(units) / f64::from(whole)
    }

    /// The paper's number of the region, 1-5, and 0 for none: what particle frames, snapshots
    /// and the region counts of `Observations` carry.
    pub fn number(&self) -> u8 {
        self.region.map_or(0, |r| r as u8)
    }
}

/// The bits of a region word that hold the region (`& 255u` in the shaders).
const REGION_MASK: u32 = 0xff;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::sediment::pickup::units_word;

    #[test]
    fn a_region_word_is_the_region_the_held_bit_and_the_wear() {
        let held = Region::Unyielded as u32 | REGION_HELD;
        // A quarter worn off by the pick-up alone, an eighth settled past a whole under Exner.
        let worn = units_word(PICKUP_WHOLE as i32 / 4);
        let built = ParticleRegion::from_word(held | units_word(-(EXNER_WHOLE as i32) / 8));
        assert_eq!(
            built.worn(true),
            -0.125,
            "a surplus settled on a held particle"
        );
        let held_unyielded = ParticleRegion::from_word(held | worn);
        assert_eq!(held_unyielded.region, Some(Region::Unyielded));
        assert!(held_unyielded.held);
        assert_eq!(held_unyielded.worn(false), 0.25);
        assert_eq!(held_unyielded.number(), 1);
        // Under Exner's balance the same bits are half a particle's loss.
        assert_eq!(held_unyielded.worn(true), 0.5);
        // Units in the word of a particle not held are no wear.
        let water = ParticleRegion::from_word(Region::Water as u32 | worn);
        assert_eq!(
            (water.number(), water.held, water.worn(false)),
            (5, false, 0.0)
        );
        assert_eq!(ParticleRegion::from_word(0), ParticleRegion::default());
    }
}
