//! Where the bed load that settles on a held particle comes from (`van_rijn_exner`).

/// The search for the held particle upstream of one at the bed's surface
/// ([`Rheology::upstream_of`](super::Rheology::upstream_of)): of the held particles at the
/// surface after the last pass, the one nearest the point dp up the flow, within dp of it.
/// Grains picked up from it land on the particle downstream at van Rijn's step; a particle with
/// none upstream (the bed's first, or one past a step down) is passed nothing.
#[derive(Clone, Copy, Debug)]
pub struct Upstream {
    at: [f32; 3],
    from: [f32; 3],
    d2: f32,
    flux: f32,
}

impl Upstream {
    /// The search for the particle upstream of the one at `from`, flowed over along the unit
    /// vector `along`, on a bed of particles `dp` apart.
    pub(super) fn new(from: [f32; 3], along: [f32; 3], dp: f32) -> Upstream {
        Upstream {
            at: std::array::from_fn(|k| from[k] - dp * along[k]),
            from,
            d2: dp * dp,
            flux: 0.0,
        }
    }

    /// Weighs neighbour `x_j`, which passed on `flux_j` in the last pass
    /// ([`NO_FLUX`](super::NO_FLUX): not a held particle at the surface).
    pub fn add(&mut self, x_j: &[f32; 4], flux_j: f32) {
        let x_j = [x_j[0], x_j[1], x_j[2]];
        if flux_j < 0.0 || x_j == self.from {
            return;
        }
        let d2: f32 = (0..3).map(|k| (x_j[k] - self.at[k]).powi(2)).sum();
        // The lesser flux of two at the same distance: the same choice in any order.
        if d2 < self.d2 || (d2 == self.d2 && flux_j < self.flux) {
            self.d2 = d2;
            self.flux = flux_j;
        }
    }

    /// The bed load the particle upstream passes on, particles per second (0: none found).
    pub fn flux(&self) -> f32 {
        self.flux
    }
}
