//! Where the bed load a held particle passes on goes, and what settles on it (`van_rijn_exner`).

/// No particle: what a particle with none downstream of it passes on leaves the bed (over its
/// end into the pit, or down a step).
pub const NO_TARGET: u32 = u32::MAX;

/// The bed-load exchange of a sediment particle with its neighbours
/// ([`Rheology::exchange_of`](super::Rheology::exchange_of)). Held at the bed's surface under
/// flowing water, it passes its load on to the particle at the bed's top in the last pass
/// nearest the point dp down the flow, within dp of it (grains picked up from it land one step
/// on), and names that one. Every particle is passed the loads of those that named it in the
/// last pass, whether it is still held or not. Each load thus goes to one particle, or off the
/// bed, and no sand is counted twice where the bed is uneven. A particle newly at the top is
/// named from the pass after; one under no flowing water names none.
#[derive(Clone, Copy, Debug)]
pub struct Exchange {
    at: [f32; 3],
    /// How far from `at` a neighbour may be named: dp, or 0 under no flow.
    radius: f32,
    id: u32,
    d2: f32,
    target: u32,
    passed: f32,
    names: bool,
}

impl Exchange {
    /// The exchange of particle `id` at `from`, flowed over along the unit vector `along`
    /// (None: under no flowing water), on a bed of particles `dp` apart.
    pub(super) fn new(id: u32, from: [f32; 3], along: Option<[f32; 3]>, dp: f32) -> Exchange {
        let flow = along.unwrap_or([0.0; 3]);
        Exchange {
            at: std::array::from_fn(|k| from[k] + dp * flow[k]),
            radius: if along.is_some() { dp } else { 0.0 },
            id,
            // Nothing lies nearer the point than 0: a particle under no flow names none.
            d2: if along.is_some() { dp * dp } else { 0.0 },
            target: NO_TARGET,
            passed: 0.0,
            names: along.is_some(),
        }
    }

    /// Weighs neighbour `id_j` at `x_j`, which in the last pass passed on `flux_j` to
    /// `target_j` ([`NO_FLUX`](super::NO_FLUX): not a held particle at the bed's top).
    pub fn add(&mut self, x_j: &[f32; 4], id_j: u32, (flux_j, target_j): (f32, u32)) {
        if flux_j < 0.0 || id_j == self.id {
            return;
        }
        if target_j == self.id {
            self.passed += flux_j;
        }
        self.weigh_target(x_j, id_j);
    }

    /// Weighs neighbour `id_j` at `x_j`, as [`Exchange::add`] does, as the particle to pass the
    /// load to only: for a caller that sums what was passed to the particle apart, in the same
    /// order (`cpu::multiphase`). Only a neighbour within [`Exchange::reach`] can be named.
    pub fn weigh(&mut self, x_j: &[f32; 4], id_j: u32, flux_j: f32) {
        if flux_j < 0.0 || id_j == self.id {
            return;
        }
        self.weigh_target(x_j, id_j);
    }

    /// The point dp down the flow and the distance from it within which a neighbour may be
    /// named (none under no flow).
    pub fn reach(&self) -> ([f32; 3], f32) {
        (self.at, self.radius)
    }

    fn weigh_target(&mut self, x_j: &[f32; 4], id_j: u32) {
        let d2: f32 = (0..3).map(|k| (x_j[k] - self.at[k]).powi(2)).sum();
        // The lesser id of two at the same distance: the same choice in any order.
        let tie = d2 == self.d2 && self.target != NO_TARGET && id_j < self.target;
        if d2 < self.d2 || tie {
            self.d2 = d2;
            self.target = id_j;
        }
    }

    /// Whether the particle passes its load to one it names (it lies under flowing water).
    /// One that does not, and that no particle named in the last pass, is passed nothing and
    /// names none: its outcome is known without weighing its neighbours.
    pub fn names(&self) -> bool {
        self.names
    }

    /// The bed load passed to the particle in the last pass, particles per second, and the
    /// particle it passes its own to ([`NO_TARGET`]: none).
    pub fn outcome(&self) -> (f32, u32) {
        (self.passed, self.target)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const DP: f32 = 0.01;

    /// Particle 5 at the origin under a flow along +x: the point it passes to is (dp, 0).
    fn at_origin() -> Exchange {
        Exchange::new(5, [0.0; 3], Some([1.0, 0.0, 0.0]), DP)
    }

    /// Of two particles as near the point dp downstream, the lower id, in either order; one a
    /// whole dp from that point, a particle held beneath the next, is not named.
    #[test]
    fn names_the_nearest_downstream_the_lower_id_on_a_tie() {
        let (above, below) = ([DP, 0.3 * DP, 0.0, 0.0], [DP, -0.3 * DP, 0.0, 0.0]);
        for order in [[(above, 9), (below, 7)], [(below, 7), (above, 9)]] {
            let mut ex = at_origin();
            for (x, id) in order {
                ex.add(&x, id, (0.1, NO_TARGET));
            }
            assert_eq!(ex.outcome().1, 7);
        }
        let mut ex = at_origin();
        ex.add(&[DP, -DP, 0.0, 0.0], 3, (0.1, NO_TARGET));
        assert_eq!(ex.outcome(), (0.0, NO_TARGET), "a dp from the point");
    }

    /// `weigh` names as `add` does and sums nothing passed; `reach` is the point dp down the
    /// flow and dp around it, nothing under no flow.
    #[test]
    fn weighing_names_as_adding_does_within_its_reach() {
        let near = ([1.6 * DP, 0.7 * DP, 0.0, 0.0], 9, (0.25, 5));
        let nearer = ([0.5 * DP, -0.6 * DP, 0.0, 0.0], 8, (0.5, 2));
        let (mut added, mut weighed) = (at_origin(), at_origin());
        for (x, id, flux) in [near, nearer] {
            added.add(&x, id, flux);
            weighed.weigh(&x, id, flux.0);
        }
        assert_eq!(added.outcome(), (0.25, 8));
        assert_eq!(weighed.outcome(), (0.0, 8));
        assert_eq!(at_origin().reach(), ([DP, 0.0, 0.0], DP));
        let still = Exchange::new(5, [0.0; 3], None, DP);
        assert_eq!(still.reach().1, 0.0);
    }

    /// It is passed the loads of those that named it and of no other; a particle not held at
    /// the surface in the last pass (`NO_FLUX`) is neither named nor read, and neither is
    /// itself.
    #[test]
    fn is_passed_only_what_was_passed_to_it() {
        let mut ex = at_origin();
        ex.add(&[-DP, 0.0, 0.0, 0.0], 1, (0.25, 5));
        ex.add(&[-DP, DP, 0.0, 0.0], 2, (0.5, 5));
        ex.add(&[-2.0 * DP, 0.0, 0.0, 0.0], 3, (4.0, 1));
        ex.add(&[DP, 0.0, 0.0, 0.0], 4, (super::super::NO_FLUX, 5));
        ex.add(&[0.0; 4], 5, (8.0, 5));
        assert_eq!(ex.outcome(), (0.75, NO_TARGET));
    }

    /// Under no flowing water it names none, even a neighbour on its own spot, and is still
    /// passed what was passed to it.
    #[test]
    fn under_no_flow_it_names_none_and_is_passed_its_loads() {
        let mut ex = Exchange::new(5, [0.0; 3], None, DP);
        ex.add(&[0.0; 4], 6, (0.0, NO_TARGET));
        ex.add(&[DP, 0.0, 0.0, 0.0], 7, (0.0, NO_TARGET));
        ex.add(&[-DP, 0.0, 0.0, 0.0], 1, (0.25, 5));
        assert_eq!(ex.outcome(), (0.25, NO_TARGET));
    }
}
