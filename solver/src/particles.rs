//! Particle state on the host and what its codes mean: the phase code each particle carries in
//! `positions[i].w`, where parked particles wait, and the region word of the rheology pass.
//! Callers ask a particle's kind here rather than decoding the bits themselves.

use crate::config::Case;

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

/// Particle state on the CPU, in the GPU's layout (see `gpu::params`).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Particles {
    /// x, y, z (z = 0 in 2-D) and, in w, the phase index as f32 bits.
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
    pub fn phase(&self, i: usize) -> u32 {
        self.positions[i][3].to_bits()
    }
}
